// Writes a small synthetic camera log for integration tests and the demo's fallback:
// a textured plane seen by a camera sliding sideways, with CAMERA_CALIBRATION first,
// ODOMETRY at 100 Hz and, with --faults, malformed messages on every input channel.
//
//   make_test_log OUT.lcmlog [--frames N] [--width W] [--height H] [--faults]

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "common/lcm/wire_check.h"
#include "common/util/command_line.h"

namespace {

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: make_test_log OUT.lcmlog [--frames N] [--width W] [--height H] [--faults]\n");
    return 2;
  }
  const std::string out = argv[1];
  const mbslam::CommandLineArgs args(argc, argv, 2);
  const int64_t frames_arg = args.GetInt("frames", 60), width_arg = args.GetInt("width", 320),
                height_arg = args.GetInt("height", 240);
  const bool faults = args.Has("faults");
  const std::string problems = args.Problems();
  if (!problems.empty() || !args.Get("faults").empty()) {
    std::fprintf(stderr, "make_test_log: %s\n", problems.empty() ? "--faults takes no value" : problems.c_str());
    return 2;
  }
  if (frames_arg < 1 || frames_arg > 100000 || width_arg < 16 || width_arg > 8192 || height_arg < 16 ||
      height_arg > 8192) {
    std::fprintf(stderr, "make_test_log: --frames 1-100000, --width and --height 16-8192\n");
    return 2;
  }
  const int frames = static_cast<int>(frames_arg), width = static_cast<int>(width_arg),
            height = static_cast<int>(height_arg);
  mbslam::ChannelOptions ch;
  mbslam::Status status;
  auto log = mbslam::LcmLogWriter::Open(out, &status);
  if (!log) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 1;
  }
  // A large random texture, blurred at two scales so it has corners to track.
  std::mt19937 rng(42);
  cv::Mat texture(height * 2, width * 4, CV_8UC1);
  cv::randu(texture, 0, 255);
  cv::Mat coarse;
  cv::GaussianBlur(texture, coarse, cv::Size(0, 0), 6.0);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.2);
  cv::addWeighted(texture, 0.5, coarse, 1.5, -64, texture);

  const int64_t t0 = 1700000000000000;
  mbslam::camera_calibration_t calib{};
  calib.utime = t0;
  calib.camera_name = "test";
  calib.width = width;
  calib.height = height;
  calib.fx = calib.fy = 0.8 * width;
  calib.cx = (width - 1) / 2.0;
  calib.cy = (height - 1) / 2.0;
  calib.distortion_model = mbslam::camera_calibration_t::DISTORTION_NONE;
  log->Write(ch.camera_calibration, t0, calib);

  int64_t odom_t = t0;
  for (int k = 0; k < frames; ++k) {
    const int64_t t = t0 + k * 33333;
    for (; odom_t <= t; odom_t += 10000) {
      mbslam::odometry_t o{};
      o.utime = odom_t;
      o.frame_id = "odom";
      o.child_frame_id = "base_link";
      o.position[0] = (odom_t - t0) * 1e-6 * 0.5;
      o.orientation[0] = 1.0;
      o.pose_covariance[0] = -1;
      o.twist_covariance[0] = -1;
      o.linear_velocity[0] = 0.5;
      log->Write(ch.odometry, odom_t, o);
    }
    const int x = (k * 7) % (texture.cols - width);
    cv::Mat view = texture(cv::Rect(x, height / 4, width, height)).clone();
    mbslam::image_t img{};
    img.utime = t;
    img.seq = k;
    img.camera_name = "test";
    img.width = width;
    img.height = height;
    img.row_stride = width;
    img.encoding = mbslam::image_t::ENCODING_GRAY8;
    img.data.assign(view.data, view.data + view.total());
    img.size = static_cast<int32_t>(img.data.size());
    log->Write(ch.camera_image, t, img);

    if (faults && k % 10 == 5) {
      std::vector<uint8_t> bytes = mbslam::EncodeLcmMessage(img);
      log->WriteRaw(ch.camera_image, t + 1, bytes.data(), bytes.size() / 3);  // truncated
      bytes[1] ^= 0x40;
      log->WriteRaw(ch.camera_image, t + 2, bytes.data(), bytes.size());      // bad fingerprint
      std::vector<uint8_t> garbage(2000);
      for (auto& b : garbage) b = static_cast<uint8_t>(rng());
      log->WriteRaw(ch.camera_calibration, t + 3, garbage.data(), garbage.size());
      log->WriteRaw(ch.odometry, t + 4, garbage.data(), 100);
      mbslam::camera_calibration_t nan_calib = calib;
      nan_calib.fx = std::nan("");
      log->Write(ch.camera_calibration, t + 5, nan_calib);
      mbslam::image_t wrong = img;
      wrong.width = width / 2;  // bytes no longer match
      wrong.row_stride = width * 4;
      log->Write(ch.camera_image, t + 6, wrong);
    }
  }
  log->Flush();
  std::printf("wrote %s: %d frames %dx%d%s\n", out.c_str(), frames, width, height,
              faults ? " with faults" : "");
  return 0;
}
