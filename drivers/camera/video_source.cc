#include "drivers/camera/video_source.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "common/util/logging.h"
#include "drivers/camera/image_codec.h"

namespace mbslam {

VideoSource::VideoSource(std::string path, double fallback_rate_hz, int64_t time_origin_us)
    : path_(std::move(path)), fallback_rate_hz_(fallback_rate_hz), time_origin_us_(time_origin_us) {}

SourceStatus VideoSource::Open() {
  if (path_.empty()) {
    return SourceStatus::Error(SourceError::kConfig, "source 'video' needs a file (--input)");
  }
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path_, ec)) {
    return SourceStatus::Error(SourceError::kNotFound, "no video file " + path_);
  }
  capture_ = std::make_unique<cv::VideoCapture>();
  try {
    capture_->open(path_, cv::CAP_FFMPEG);
  } catch (const cv::Exception& e) {
    return SourceStatus::Error(SourceError::kIo, path_ + ": " + e.what());
  }
  if (!capture_->isOpened()) {
    return SourceStatus::Error(SourceError::kIo, path_ + ": not a video the FFmpeg backend can read");
  }
  fps_ = capture_->get(cv::CAP_PROP_FPS);
  if (!(fps_ > 0.0) || !std::isfinite(fps_)) fps_ = fallback_rate_hz_;
  const double count = capture_->get(cv::CAP_PROP_FRAME_COUNT);
  num_frames_ = count > 0 && std::isfinite(count) ? static_cast<int64_t>(count) : -1;
  next_index_ = 0;
  last_utime_ = -1;
  use_container_time_ = true;
  return SourceStatus::Ok();
}

void VideoSource::Close() { capture_.reset(); }

SourceStatus VideoSource::Rewind() {
  Close();
  return Open();
}

bool VideoSource::SeekToIndex(int64_t index) {
  // Decoding through is exact where container seeking is not; grab() skips the
  // colour conversion.
  while (next_index_ < index && capture_ && capture_->grab()) {
    last_utime_ = -1;
    ++next_index_;
  }
  return next_index_ == index;
}

FrameSource::ReadResult VideoSource::Next(Frame* frame, SourceStatus* status) {
  if (!capture_) {
    *status = SourceStatus::Error(SourceError::kIo, "video not open");
    return ReadResult::kError;
  }
  cv::Mat image;
  bool ok = false;
  try {
    ok = capture_->read(image);
  } catch (const cv::Exception& e) {
    *status = SourceStatus::Error(SourceError::kIo, path_ + ": " + e.what());
    return ReadResult::kError;
  }
  if (!ok || image.empty()) {
    if (num_frames_ > 0 && next_index_ < num_frames_ - 1) {
      MBSLAM_LOG(WARNING) << path_ << ": video ended after " << next_index_ << " of "
                          << num_frames_ << " frames (truncated file?)";
    }
    return ReadResult::kEnd;
  }
  *frame = Frame();
  frame->index = next_index_;
  std::ostringstream origin;
  origin << path_ << " frame " << next_index_;
  frame->origin = origin.str();
  int64_t t = static_cast<int64_t>(std::llround(static_cast<double>(next_index_) * 1e6 / fps_));
  if (use_container_time_) {
    const double msec = capture_->get(cv::CAP_PROP_POS_MSEC);
    const int64_t pts = std::isfinite(msec) ? static_cast<int64_t>(std::llround(msec * 1000.0)) : -1;
    if (pts >= 0 && pts > last_utime_ - time_origin_us_) {
      t = pts;
    } else if (next_index_ > 0) {
      use_container_time_ = false;  // times do not increase: use index / fps from here on
      MBSLAM_LOG(WARNING) << path_ << ": container times do not increase; timing frames by "
                          << fps_ << " Hz";
    }
  }
  frame->utime = time_origin_us_ + t;
  if (frame->utime <= last_utime_) frame->utime = last_utime_ + 1;
  last_utime_ = frame->utime;
  ++next_index_;
  bool changed = false;
  const Status normalized = NormalizeImage(image, &frame->image, &changed);
  if (!normalized.ok()) {
    *status = SourceStatus::Error(SourceError::kIo, frame->origin + ": " + normalized.message());
    return ReadResult::kBadFrame;
  }
  *status = SourceStatus::Ok();
  return ReadResult::kFrame;
}

std::string VideoSource::description() const {
  std::ostringstream os;
  os << "video " << path_ << " (" << num_frames_ << " frames at " << fps_ << " Hz)";
  return os.str();
}

}  // namespace mbslam
