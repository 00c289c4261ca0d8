#ifndef MBSLAM_DRIVERS_CAMERA_VIDEO_SOURCE_H_
#define MBSLAM_DRIVERS_CAMERA_VIDEO_SOURCE_H_

// Video files through OpenCV's FFmpeg backend. Frame times are the container's
// presentation times (CAP_PROP_POS_MSEC) when they increase, else index / fps.

#include <opencv2/videoio.hpp>

#include <memory>
#include <string>

#include "drivers/camera/frame_source.h"

namespace mbslam {

class VideoSource : public FrameSource {
 public:
  // `fallback_rate_hz` is used when the file has no frame rate; `time_origin_us` is
  // added to every frame time.
  VideoSource(std::string path, double fallback_rate_hz, int64_t time_origin_us);

  SourceStatus Open() override;
  void Close() override;
  ReadResult Next(Frame* frame, SourceStatus* status) override;
  bool is_live() const override { return false; }
  int64_t num_frames() const override { return num_frames_; }
  SourceStatus Rewind() override;
  bool SeekToIndex(int64_t index) override;
  std::string description() const override;

 private:
  std::string path_;
  double fallback_rate_hz_;
  int64_t time_origin_us_;
  std::unique_ptr<cv::VideoCapture> capture_;
  double fps_ = 0.0;
  int64_t num_frames_ = -1;
  int64_t next_index_ = 0;
  int64_t last_utime_ = -1;
  bool use_container_time_ = true;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_VIDEO_SOURCE_H_
