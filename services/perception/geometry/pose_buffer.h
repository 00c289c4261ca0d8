#ifndef MBSLAM_SERVICES_PERCEPTION_GEOMETRY_POSE_BUFFER_H_
#define MBSLAM_SERVICES_PERCEPTION_GEOMETRY_POSE_BUFFER_H_

// Time-stamped poses (e.g. odometry odom_from_base) with interpolation on SE(3) to an
// arbitrary timestamp (thesis sec. 3.8.1: odometry interpolated to image time).

#include <cstdint>
#include <deque>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct StampedPose {
  int64_t utime = 0;  // µs
  Rigid3d pose;
};

enum class InterpolationResult {
  kOk,           // bracketed by two samples at most max_gap_us apart
  kEmpty,        // no samples
  kBeforeFirst,  // the time is older than every sample
  kAfterLast,    // the time is newer than every sample (wait for more, or extrapolate)
  kGapTooLarge,  // bracketing samples are further apart than max_gap_us
};

const char* InterpolationResultName(InterpolationResult result);

class PoseBuffer {
 public:
  // max_gap_us: largest spacing of samples to interpolate across.
  // max_samples: older samples are dropped beyond this count.
  explicit PoseBuffer(int64_t max_gap_us = 500000, size_t max_samples = 10000)
      : max_gap_us_(max_gap_us), max_samples_(max_samples) {}

  // Appends a sample. Rejects non-finite poses and times that do not increase (the
  // caller counts these; the buffer stays as it was).
  Status Insert(int64_t utime, const Rigid3d& pose);

  // Pose at `utime` by geodesic interpolation between the bracketing samples. A time
  // equal to a sample returns it exactly.
  InterpolationResult Interpolate(int64_t utime, Rigid3d* pose) const;

  // Pose at a time after the last sample, continuing the motion between the last two
  // samples (constant twist). False with fewer than two samples or a time before the
  // last one.
  bool Extrapolate(int64_t utime, Rigid3d* pose) const;

  // Drops samples older than the last one at or before `utime`.
  void PruneBefore(int64_t utime);
  void Clear() { samples_.clear(); }

  size_t size() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  int64_t first_utime() const { return samples_.front().utime; }
  int64_t last_utime() const { return samples_.back().utime; }

 private:
  int64_t max_gap_us_;
  size_t max_samples_;
  std::deque<StampedPose> samples_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_GEOMETRY_POSE_BUFFER_H_
