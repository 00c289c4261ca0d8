#ifndef MBSLAM_DRIVERS_CAMERA_V4L2_SOURCE_H_
#define MBSLAM_DRIVERS_CAMERA_V4L2_SOURCE_H_

// V4L2 (USB / UVC) cameras through OpenCV's V4L2 backend. The device node is checked
// before OpenCV sees it, so a missing camera, a permission problem and a refused
// mode each get their own message; OpenCV's select() timeout is set from
// frame_timeout_s so an unplugged camera cannot block for long.

#include <opencv2/videoio.hpp>

#include <memory>
#include <string>

#include "drivers/camera/camera_driver_options.h"
#include "drivers/camera/frame_source.h"

namespace mbslam {

class V4l2Source : public FrameSource {
 public:
  explicit V4l2Source(V4l2Options options);

  SourceStatus Open() override;
  void Close() override;
  ReadResult Next(Frame* frame, SourceStatus* status) override;
  bool is_live() const override { return true; }
  std::string description() const override { return description_; }

 private:
  V4l2Options options_;
  std::string device_;
  std::unique_ptr<cv::VideoCapture> capture_;
  std::string description_ = "V4L2 camera";
  int64_t next_index_ = 0;
  int64_t last_utime_ = 0;
};

// "/dev/video0" for "0", else the text itself.
std::string V4l2DevicePath(const std::string& device);

// Checks a device node: kNoCamera if it does not exist, kAccess if it cannot be
// opened for reading and writing, kConfig if it is not a character device.
SourceStatus CheckV4l2DeviceNode(const std::string& path);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_V4L2_SOURCE_H_
