#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_PREDICTED_VOLUME_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_PREDICTED_VOLUME_H_

// Space a moving object is expected to occupy (thesis sec. 6.3, fig. 6.4): the particle
// cloud of its tracker propagated with the particles' own velocities to a future time,
// then an oriented box that holds a given share of the particle mass, grown by the
// object's extent (and a margin for unmodelled acceleration). Same fields as
// PredictedVolumeOutput (pipeline/outputs.h) and predicted_volume_t.
//
// The box: its axes are the cloud's principal directions (the horizontal ones about the
// up direction when it is known, so the box stands upright); along each axis the cloud is
// measured robustly (median and central `probability` quantile range), and the box of
// particle centres is the smallest scaled copy of that per-axis box (an L-infinity ball
// in the normalised coordinates) that holds `probability` of the particles. By
// construction at least that share of the particle centres lies inside it; that share is
// reported as `probability`.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/config/options.h"
#include "services/perception/objects/object_extent.h"

namespace mbslam {

struct PredictedVolume {
  int64_t utime = 0;                                 // time the prediction is for (µs)
  int64_t horizon_us = 0;                            // utime minus the time of the estimate (µs)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // box centre, world (units)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world_from_box
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();  // half sizes along the box axes (units)
  double probability = 0.0;  // share of the particle mass whose object centre is inside [0, 1]

  bool Contains(const Eigen::Vector3d& point_in_world) const;
};

struct PredictedVolumeOptions {
  int64_t horizon_us = 1000000;  // furthest prediction (µs)
  int64_t step_us = 250000;      // spacing of the predictions (µs)
  bool include_current = true;   // a volume at horizon 0 first
  double probability = 0.9;      // particle mass each box holds (0, 1]
  double accel_margin = 0.5;  // unmodelled acceleration: half sizes grow by a t^2 / 2 (units/s^2)
  int max_samples = 256;      // particles used (deterministic weighted subsample) (count)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(horizon_us, 0);
    MBSLAM_CHECK_OPTION_GT(step_us, 0);
    MBSLAM_CHECK_OPTION(probability > 0.0 && probability <= 1.0);
    MBSLAM_CHECK_OPTION_GE(accel_margin, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_samples, 10);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("horizon_us", &horizon_us, "furthest prediction (us)");
    v("step_us", &step_us, "spacing of the predictions (us)");
    v("include_current", &include_current, "a volume at horizon 0 first");
    v("probability", &probability, "particle mass each box holds (0, 1]");
    v("accel_margin", &accel_margin, "unmodelled acceleration margin a t^2 / 2 (units/s^2)");
    v("max_samples", &max_samples, "particles used, weighted subsample (count)");
  }
};

// The box around equally weighted object-centre positions (world), holding `probability`
// of them, grown by the object's half sizes along the box axes and by `margin` (units).
// `up`: the world's up direction if known (unit). Empty input gives a zero box.
PredictedVolume BoundingVolume(const std::vector<Eigen::Vector3d>& centers,
                               const std::optional<Eigen::Vector3d>& up, const ObjectExtent& extent,
                               double probability, double margin);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_PREDICTED_VOLUME_H_
