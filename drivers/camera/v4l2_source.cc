#include "drivers/camera/v4l2_source.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "drivers/camera/image_codec.h"

namespace mbslam {
namespace {

std::string ListVideoNodes() {
  std::string nodes;
  std::error_code ec;
  for (std::filesystem::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind("video", 0) == 0) nodes += (nodes.empty() ? "" : " ") + it->path().string();
  }
  return nodes;
}

std::string FourccText(double value) {
  const int v = static_cast<int>(value);
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((v >> (8 * i)) & 0xFF);
    s += std::isprint(static_cast<unsigned char>(c)) ? c : '?';
  }
  return s;
}

}  // namespace

std::string V4l2DevicePath(const std::string& device) {
  if (!device.empty() && std::all_of(device.begin(), device.end(),
                                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
    return "/dev/video" + device;
  }
  return device;
}

SourceStatus CheckV4l2DeviceNode(const std::string& path) {
  struct stat st {};
  if (stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) {
      const std::string others = ListVideoNodes();
      return SourceStatus::Error(
          SourceError::kNoCamera,
          "no V4L2 camera: " + path + " does not exist (" +
              (others.empty() ? std::string("no /dev/video* devices at all; is a USB camera plugged in?")
                              : "devices present: " + others) +
              ")");
    }
    return SourceStatus::Error(SourceError::kAccess,
                               "cannot inspect " + path + ": " + std::strerror(errno));
  }
  if (!S_ISCHR(st.st_mode)) {
    return SourceStatus::Error(SourceError::kConfig, path + " is not a V4L2 device (not a character device)");
  }
  if (access(path.c_str(), R_OK | W_OK) != 0) {
    return SourceStatus::Error(SourceError::kAccess,
                               "no permission to open " + path +
                                   " (add the user to group 'video')");
  }
  return SourceStatus::Ok();
}

V4l2Source::V4l2Source(V4l2Options options)
    : options_(std::move(options)), device_(V4l2DevicePath(options_.device)) {}

void V4l2Source::Close() { capture_.reset(); }

SourceStatus V4l2Source::Open() {
  Close();
  SourceStatus node = CheckV4l2DeviceNode(device_);
  if (!node.ok()) return node;
  // OpenCV's V4L2 backend reads this once, at its first capture; 10 s otherwise.
  const int timeout_s = std::max(1, static_cast<int>(std::ceil(options_.frame_timeout_s)));
  setenv("OPENCV_VIDEOIO_V4L_SELECT_TIMEOUT", std::to_string(timeout_s).c_str(), 0);
  capture_ = std::make_unique<cv::VideoCapture>();
  try {
    capture_->open(device_, cv::CAP_V4L2);
  } catch (const cv::Exception& e) {
    capture_.reset();
    return SourceStatus::Error(SourceError::kAccess, "cannot open " + device_ + ": " + e.what());
  }
  if (!capture_->isOpened()) {
    capture_.reset();
    return SourceStatus::Error(SourceError::kAccess,
                               "cannot open " + device_ +
                                   " as a capture device (busy, or not a camera node)");
  }
  if (!options_.fourcc.empty()) {
    const std::string& f = options_.fourcc;
    capture_->set(cv::CAP_PROP_FOURCC, cv::VideoWriter::fourcc(f[0], f[1], f[2], f[3]));
  }
  if (options_.width > 0) capture_->set(cv::CAP_PROP_FRAME_WIDTH, options_.width);
  if (options_.height > 0) capture_->set(cv::CAP_PROP_FRAME_HEIGHT, options_.height);
  if (options_.fps > 0) capture_->set(cv::CAP_PROP_FPS, options_.fps);
  const int width = static_cast<int>(capture_->get(cv::CAP_PROP_FRAME_WIDTH));
  const int height = static_cast<int>(capture_->get(cv::CAP_PROP_FRAME_HEIGHT));
  const double fps = capture_->get(cv::CAP_PROP_FPS);
  const std::string fourcc = FourccText(capture_->get(cv::CAP_PROP_FOURCC));
  std::ostringstream got;
  got << width << "x" << height << " " << fourcc << " @ " << fps << " Hz";
  const bool size_bad = (options_.width > 0 && width != options_.width) ||
                        (options_.height > 0 && height != options_.height);
  const bool fourcc_bad = !options_.fourcc.empty() && fourcc != options_.fourcc;
  const bool fps_bad = options_.fps > 0 && fps > 0 && std::abs(fps - options_.fps) > 0.5;
  if (size_bad || fourcc_bad || fps_bad) {
    std::ostringstream want;
    want << (options_.width > 0 ? std::to_string(options_.width) : "*") << "x"
         << (options_.height > 0 ? std::to_string(options_.height) : "*") << " "
         << (options_.fourcc.empty() ? "*" : options_.fourcc) << " @ " << options_.fps << " Hz";
    capture_.reset();
    return SourceStatus::Error(SourceError::kBadMode, device_ + " does not support " + want.str() +
                                                          " (it offers " + got.str() + ")");
  }
  description_ = "V4L2 camera " + device_ + " (" + got.str() + ")";
  return SourceStatus::Ok();
}

FrameSource::ReadResult V4l2Source::Next(Frame* frame, SourceStatus* status) {
  if (!capture_) {
    *status = SourceStatus::Error(SourceError::kDisconnected, device_ + " not open");
    return ReadResult::kError;
  }
  cv::Mat image;
  bool ok = false;
  try {
    ok = capture_->grab();
    if (ok) ok = capture_->retrieve(image);
  } catch (const cv::Exception& e) {
    ok = false;
  }
  const int64_t now = WallUtime();
  if ((!ok || image.empty()) && ShutdownRequested()) return ReadResult::kEnd;  // EINTR from SIGINT
  if (!ok || image.empty()) {
    std::error_code ec;
    const bool gone = !std::filesystem::exists(device_, ec);
    std::ostringstream msg;
    msg << description_ << ": "
        << (gone ? "device node disappeared (unplugged)"
                 : "no frame within " + std::to_string(options_.frame_timeout_s) + " s (stalled)");
    *status = SourceStatus::Error(SourceError::kDisconnected, msg.str());
    return ReadResult::kError;
  }
  *frame = Frame();
  frame->index = next_index_++;
  frame->origin = "frame " + std::to_string(frame->index);
  // The driver's buffer time is CLOCK_MONOTONIC; map it onto the wall clock when it is
  // plausible (within 1 s of now), else use the time of the read.
  int64_t utime = now;
  const double msec = capture_->get(cv::CAP_PROP_POS_MSEC);
  if (std::isfinite(msec) && msec > 0) {
    const int64_t age = MonotonicUtime() - static_cast<int64_t>(std::llround(msec * 1000.0));
    if (age >= 0 && age < kUsecPerSec) utime = now - age;
  }
  if (utime <= last_utime_) utime = last_utime_ + 1;
  last_utime_ = utime;
  frame->utime = utime;
  bool changed = false;
  const Status normalized = NormalizeImage(image, &frame->image, &changed);
  if (!normalized.ok()) {
    *status = SourceStatus::Error(SourceError::kIo, description_ + ": " + normalized.message());
    return ReadResult::kBadFrame;
  }
  *status = SourceStatus::Ok();
  return ReadResult::kFrame;
}

}  // namespace mbslam
