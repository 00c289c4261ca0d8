#include "services/perception/geometry/pose_buffer.h"

#include <algorithm>
#include <cstdint>

namespace mbslam {
namespace {

// later - earlier for later >= earlier, exact over the whole int64 range (the signed
// difference overflowed for sample times read from files, e.g. -9e18 and 9e18 µs).
uint64_t Span(int64_t earlier, int64_t later) {
  return static_cast<uint64_t>(later) - static_cast<uint64_t>(earlier);
}

}  // namespace

const char* InterpolationResultName(InterpolationResult result) {
  switch (result) {
    case InterpolationResult::kOk: return "ok";
    case InterpolationResult::kEmpty: return "no samples";
    case InterpolationResult::kBeforeFirst: return "before the first sample";
    case InterpolationResult::kAfterLast: return "after the last sample";
    case InterpolationResult::kGapTooLarge: return "gap between samples too large";
  }
  return "unknown";
}

Status PoseBuffer::Insert(int64_t utime, const Rigid3d& pose) {
  if (!pose.IsFinite()) return Status::Error("non-finite pose");
  if (std::abs(pose.rotation.norm() - 1.0) > 1e-3) return Status::Error("quaternion not unit");
  if (!samples_.empty() && utime <= samples_.back().utime) {
    return Status::Error("time did not increase (" + std::to_string(utime) + " after " +
                         std::to_string(samples_.back().utime) + ")");
  }
  samples_.push_back(StampedPose{utime, pose});
  while (samples_.size() > max_samples_) samples_.pop_front();
  return Status::Ok();
}

InterpolationResult PoseBuffer::Interpolate(int64_t utime, Rigid3d* pose) const {
  if (samples_.empty()) return InterpolationResult::kEmpty;
  if (utime < samples_.front().utime) return InterpolationResult::kBeforeFirst;
  if (utime > samples_.back().utime) return InterpolationResult::kAfterLast;
  auto upper = std::lower_bound(samples_.begin(), samples_.end(), utime,
                                [](const StampedPose& s, int64_t t) { return s.utime < t; });
  if (upper->utime == utime) {
    *pose = upper->pose;
    return InterpolationResult::kOk;
  }
  const StampedPose& b = *upper;
  const StampedPose& a = *(upper - 1);
  const uint64_t span = Span(a.utime, b.utime);
  if (max_gap_us_ < 0 || span > static_cast<uint64_t>(max_gap_us_)) {
    return InterpolationResult::kGapTooLarge;
  }
  const double t = static_cast<double>(Span(a.utime, utime)) / static_cast<double>(span);
  *pose = Rigid3d::Interpolate(a.pose, b.pose, t);
  return InterpolationResult::kOk;
}

bool PoseBuffer::Extrapolate(int64_t utime, Rigid3d* pose) const {
  if (samples_.size() < 2 || utime < samples_.back().utime) return false;
  const StampedPose& b = samples_.back();
  const StampedPose& a = samples_[samples_.size() - 2];
  const double t = static_cast<double>(Span(a.utime, utime)) / static_cast<double>(Span(a.utime, b.utime));
  *pose = Rigid3d::Interpolate(a.pose, b.pose, t);  // t > 1 continues the geodesic
  return true;
}

void PoseBuffer::PruneBefore(int64_t utime) {
  while (samples_.size() >= 2 && samples_[1].utime <= utime) samples_.pop_front();
}

}  // namespace mbslam
