#include "drivers/odometry_bridge/image_odometry_sync.h"

#include <sstream>

#include "common/util/time.h"

namespace mbslam {

ImageOdometrySync::ImageOdometrySync(const Rigid3d& base_from_cam, int64_t max_gap_us,
                                     int64_t max_wait_us, size_t max_pending)
    : base_from_cam_(base_from_cam),
      max_wait_us_(max_wait_us),
      max_pending_(max_pending),
      buffer_(max_gap_us, 100000) {}

InterpolationResult ImageOdometrySync::Interpolate(int64_t utime, Rigid3d* odom_from_base) const {
  return buffer_.Interpolate(utime, odom_from_base);
}

ImageOdometry ImageOdometrySync::Resolve(const ImageStamp& image) {
  ImageOdometry r;
  r.image = image;
  r.frame_id = frame_id_;
  r.result = buffer_.Interpolate(image.utime, &r.odom_from_base);
  if (r.result == InterpolationResult::kOk) {
    r.odom_from_cam = r.odom_from_base * base_from_cam_;
    ++stats_.synced;
  } else {
    std::ostringstream os;
    if (buffer_.empty()) {
      os << "no odometry yet";
    } else {
      os << "odometry covers [" << buffer_.first_utime() << ", " << buffer_.last_utime() << "] us";
    }
    r.detail = os.str();
    switch (r.result) {
      case InterpolationResult::kBeforeFirst: ++stats_.before_first; break;
      case InterpolationResult::kGapTooLarge: ++stats_.in_gap; break;
      default: ++stats_.after_last; break;
    }
  }
  return r;
}

void ImageOdometrySync::AddOdometry(const OdometrySample& sample, std::vector<ImageOdometry>* out) {
  if (!buffer_.Insert(sample.utime, sample.odom_from_base).ok()) {
    ++stats_.odometry_rejected;
    return;
  }
  frame_id_ = sample.frame_id;
  while (!pending_.empty() && pending_.front().utime <= buffer_.last_utime()) {
    out->push_back(Resolve(pending_.front()));
    pending_.pop_front();
  }
}

void ImageOdometrySync::AddImage(const ImageStamp& image, std::vector<ImageOdometry>* out) {
  ++stats_.images;
  // Images that waited longer than max_wait (by the newest image's time) give up.
  while (!pending_.empty() && image.utime - pending_.front().utime > max_wait_us_) {
    out->push_back(Resolve(pending_.front()));
    pending_.pop_front();
  }
  if (!buffer_.empty() && image.utime <= buffer_.last_utime() && pending_.empty()) {
    out->push_back(Resolve(image));
    return;
  }
  if (buffer_.empty() || image.utime > buffer_.last_utime() || !pending_.empty()) {
    if (pending_.size() >= max_pending_) {
      ++stats_.pending_overflow;
      out->push_back(Resolve(pending_.front()));
      pending_.pop_front();
    }
    pending_.push_back(image);
  }
}

void ImageOdometrySync::Flush(std::vector<ImageOdometry>* out) {
  while (!pending_.empty()) {
    out->push_back(Resolve(pending_.front()));
    pending_.pop_front();
  }
}

}  // namespace mbslam
