// mbslam-overlay: draws one frame's published tracks (PERCEPTION_TRACKS of a run log)
// over the sequence image: static green, moving with an object red, moving without
// an object yellow, occluded blue, new white; object hulls outlined.
//
//   mbslam-overlay --run OUT.lcmlog --sequence SEQ_DIR --frame N --out FILE.png

#include <cmath>
#include <cstdio>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/util/command_line.h"
#include "mbslam/tracks_t.hpp"

int main(int argc, char** argv) {
  const mbslam::CommandLineArgs args(argc, argv);
  const std::string run = args.Get("run"), seq = args.Get("sequence"), out = args.Get("out", "overlay.png");
  const long long frame = args.GetInt("frame", 0);
  if (const std::string problems = args.Problems(); !problems.empty() || run.empty() || seq.empty()) {
    std::fprintf(stderr, "%s%susage: mbslam-overlay --run OUT.lcmlog --sequence SEQ_DIR --frame N --out FILE.png\n",
                 problems.c_str(), problems.empty() ? "" : "\n");
    return 2;
  }
  std::vector<mbslam::LcmLogEvent> events;
  mbslam::ReadLcmLog(run, &events, mbslam::ChannelOptions().perception_tracks);
  for (const auto& e : events) {
    mbslam::tracks_t t{};
    if (!mbslam::DecodeLcmMessage(e.data.data(), e.data.size(), &t).ok() || t.frame_seq != frame) continue;
    char name[64];
    std::snprintf(name, sizeof(name), "/images/%06lld.png", frame);
    cv::Mat img = cv::imread(seq + name, cv::IMREAD_COLOR);
    if (img.empty()) img = cv::Mat(t.height, t.width, CV_8UC3, cv::Scalar(0, 0, 0));
    for (const auto& h : t.hulls) {
      std::vector<cv::Point> pts;
      for (int k = 0; k < h.num_points; ++k) pts.emplace_back(static_cast<int>(h.u[k]), static_cast<int>(h.v[k]));
      cv::polylines(img, pts, true, cv::Scalar(0, 0, 255), 2);
      if (!pts.empty()) cv::putText(img, std::to_string(h.body_id), pts[0], cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 255), 2);
    }
    for (const auto& f : t.tracks) {
      cv::Scalar c(0, 255, 0);
      if (f.flags & mbslam::feature_track_t::FLAG_NEW) c = cv::Scalar(255, 255, 255);
      else if (f.flags & mbslam::feature_track_t::FLAG_OCCLUDED) c = cv::Scalar(255, 0, 0);
      else if (f.body_id > 0) c = cv::Scalar(0, 0, 255);
      else if (f.body_id < 0) c = cv::Scalar(0, 255, 255);
      const cv::Point p(static_cast<int>(std::lround(f.u)), static_cast<int>(std::lround(f.v)));
      cv::circle(img, p, 2, c, -1);
      if (std::isfinite(f.prev_u)) {
        cv::line(img, p, cv::Point(static_cast<int>(std::lround(f.prev_u)), static_cast<int>(std::lround(f.prev_v))), c, 1);
      }
    }
    cv::imwrite(out, img);
    std::printf("wrote %s (%d tracks, %d hulls)\n", out.c_str(), t.num_tracks, t.num_hulls);
    return 0;
  }
  std::fprintf(stderr, "frame %lld not in %s\n", frame, run.c_str());
  return 1;
}
