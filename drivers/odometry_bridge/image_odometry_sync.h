#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_IMAGE_ODOMETRY_SYNC_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_IMAGE_ODOMETRY_SYNC_H_

// Odometry interpolated to image timestamps on SE(3) (thesis sec. 3.8.1), with the
// camera pose odom_from_cam = odom_from_base(t_image) * base_from_cam. Images newer
// than the newest odometry wait for it (bounded, in message time); images outside
// the odometry, or in a gap too large to interpolate, are reported with the reason.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "drivers/odometry_bridge/odometry_sample.h"
#include "services/perception/geometry/pose_buffer.h"

namespace mbslam {

struct ImageStamp {
  int64_t utime = 0;  // µs
  int64_t seq = 0;
  std::string camera_name;
};

struct ImageOdometry {
  ImageStamp image;
  InterpolationResult result = InterpolationResult::kEmpty;
  Rigid3d odom_from_base;  // valid when result == kOk
  Rigid3d odom_from_cam;   // valid when result == kOk
  std::string frame_id;    // odometry frame
  // For a failure: what the odometry covered, e.g. "odometry covers [t0, t1]".
  std::string detail;
};

struct ImageSyncStats {
  int64_t images = 0;
  int64_t synced = 0;
  int64_t before_first = 0;   // older than all odometry
  int64_t after_last = 0;     // odometry never caught up (waited too long / end of input)
  int64_t in_gap = 0;         // odometry gap too large
  int64_t odometry_rejected = 0;  // samples out of order or invalid
  int64_t pending_overflow = 0;   // images given up because too many waited
};

class ImageOdometrySync {
 public:
  ImageOdometrySync(const Rigid3d& base_from_cam, int64_t max_gap_us, int64_t max_wait_us,
                    size_t max_pending);

  // Adds odometry; images it now covers are appended to *out.
  void AddOdometry(const OdometrySample& sample, std::vector<ImageOdometry>* out);
  // Adds an image; appended to *out at once unless it must wait for odometry.
  void AddImage(const ImageStamp& image, std::vector<ImageOdometry>* out);
  // Resolves every waiting image (at the end of the input).
  void Flush(std::vector<ImageOdometry>* out);

  // Interpolates one time without queueing.
  InterpolationResult Interpolate(int64_t utime, Rigid3d* odom_from_base) const;

  const ImageSyncStats& stats() const { return stats_; }
  size_t pending() const { return pending_.size(); }
  const Rigid3d& base_from_cam() const { return base_from_cam_; }

 private:
  ImageOdometry Resolve(const ImageStamp& image);

  Rigid3d base_from_cam_;
  int64_t max_wait_us_;
  size_t max_pending_;
  PoseBuffer buffer_;
  std::string frame_id_ = "odom";
  std::deque<ImageStamp> pending_;
  ImageSyncStats stats_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_IMAGE_ODOMETRY_SYNC_H_
