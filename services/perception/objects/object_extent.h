#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_OBJECT_EXTENT_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_OBJECT_EXTENT_H_

// The metric size of a moving object from its feature tracks (what the predicted volumes
// are built around). The tracks' bearings are placed at the tracker's depth of the
// object (all at the same camera depth: the object is seen as a slab facing the camera)
// and measured in a "view box" frame: x the horizontal viewing direction, y to the left,
// z up (the ground plane's normal). Width and height come from robust percentiles of the
// track positions, scaled to the full size under a uniform spread of features
// (size = percentile range / (high - low)); the depth of the object along the view,
// which one view cannot see, is assumed to be `depth_to_width_ratio` times its width.
// Successive images are smoothed exponentially.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/config/options.h"
#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct ObjectExtent {
  bool valid = false;
  Eigen::Quaterniond world_from_box = Eigen::Quaterniond::Identity();  // box axes in the world
  Eigen::Vector3d size = Eigen::Vector3d::Zero();  // full sizes along the box axes (units)
  // Box centre minus the object's reference point (the point the tracker follows), world
  // axes (units).
  Eigen::Vector3d center_offset = Eigen::Vector3d::Zero();

  // Half sizes of the smallest box with axes `world_from_axes` (columns) that contains
  // this box (zero when not valid).
  Eigen::Vector3d HalfSizeAlong(const Eigen::Matrix3d& world_from_axes) const;
  // Full sizes along the axes of a frame, e.g. the object frame of ObjectOutput::extent.
  Eigen::Vector3d SizeAlong(const Eigen::Quaterniond& world_from_frame) const {
    return 2.0 * HalfSizeAlong(world_from_frame.toRotationMatrix());
  }
};

struct ObjectExtentOptions {
  double low_percentile = 0.05;       // robust lower percentile of the track positions [0, 0.5)
  double high_percentile = 0.95;      // robust upper percentile (0.5, 1]
  double depth_to_width_ratio = 1.0;  // unseen depth of the object / its width (ratio)
  double min_size = 0.2;              // each size at least (units)
  double max_size = 30.0;             // each size at most (units)
  double smoothing = 0.3;  // exponential smoothing gain of a new image [0, 1] (1 = no memory)
  int min_tracks = 3;      // fewer tracks: the image is ignored (count)

  bool Check() const {
    MBSLAM_CHECK_OPTION(low_percentile >= 0.0 && low_percentile < 0.5);
    MBSLAM_CHECK_OPTION(high_percentile > 0.5 && high_percentile <= 1.0);
    MBSLAM_CHECK_OPTION_GT(depth_to_width_ratio, 0.0);
    MBSLAM_CHECK_OPTION_GT(min_size, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_size, min_size);
    MBSLAM_CHECK_OPTION(smoothing > 0.0 && smoothing <= 1.0);
    MBSLAM_CHECK_OPTION_GE(min_tracks, 2);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("low_percentile", &low_percentile, "robust lower percentile of track positions [0, 0.5)");
    v("high_percentile", &high_percentile, "robust upper percentile (0.5, 1]");
    v("depth_to_width_ratio", &depth_to_width_ratio, "unseen depth of the object / its width");
    v("min_size", &min_size, "each size at least (units)");
    v("max_size", &max_size, "each size at most (units)");
    v("smoothing", &smoothing, "smoothing gain of a new image [0, 1] (1 = no memory)");
    v("min_tracks", &min_tracks, "fewer tracks: the image is ignored (count)");
  }
};

class ObjectExtentEstimator {
 public:
  explicit ObjectExtentEstimator(const ObjectExtentOptions& options = ObjectExtentOptions());

  // One image: the object's tracks and its reference bearing (normalised undistorted
  // coordinates), the tracker's depth of the reference point along the optical axis
  // (units) and the world's up direction (the ground plane's normal; need not be unit).
  // Fails (state unchanged) on bad input or too few tracks.
  Status Update(const Rigid3d& cam_from_world, const std::vector<Eigen::Vector2d>& track_xy,
                const Eigen::Vector2d& reference_xy, double depth, const Eigen::Vector3d& up);

  const ObjectExtent& extent() const { return extent_; }
  int num_updates() const { return num_updates_; }
  // The world's units were multiplied by `factor`.
  void RescaleWorld(double factor);
  void Reset();

 private:
  ObjectExtentOptions options_;
  ObjectExtent extent_;
  Eigen::Vector3d offset_in_box_ = Eigen::Vector3d::Zero();
  int num_updates_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_OBJECT_EXTENT_H_
