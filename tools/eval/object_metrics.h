#ifndef MBSLAM_TOOLS_EVAL_OBJECT_METRICS_H_
#define MBSLAM_TOOLS_EVAL_OBJECT_METRICS_H_

// Moving-object metrics: per-object trajectory error with and without scale alignment,
// relative-scale error, depth error over time, and the hit rate of predicted volumes.
//
// Estimates live in the estimate's world frame (map units); `gt_from_est` (e.g. the
// Sim(3) alignment of the camera trajectories) maps them into the ground-truth world.
// A monocular object trajectory is only known up to a scale about the camera
// (thesis ch. 6: t_wo(s) = R_cw^T (s t_co - t_cw)), so the scale-aligned error uses the
// one-parameter family p(s) = c + s (p - c), c = true camera centre, and the
// relative-scale error is |s - 1| for the best s.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/config/options.h"
#include "common/util/status.h"
#include "tools/eval/camera_metrics.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

struct PredictedVolume {
  int64_t utime = 0;                                 // time the prediction is for (µs)
  int64_t horizon_us = 0;                            // utime minus the time of the estimate (µs)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // world (estimate units)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world_from_box
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();            // (estimate units)
  double probability = 0.0;

  // True if `point` (estimate world frame) is inside the box.
  bool Contains(const Eigen::Vector3d& point) const;
  // True if the box and the box (center, world_from_box, half_extent) share a point
  // (separating axis test).
  bool Overlaps(const Eigen::Vector3d& other_center, const Eigen::Quaterniond& other_orientation,
                const Eigen::Vector3d& other_half_extent) const;
};

struct ObjectSample {
  int64_t utime = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world (estimate units)
  double depth = -1.0;  // along the optical axis (estimate units); < 0 = not given
  std::vector<PredictedVolume> volumes;
};

struct ObjectEstimate {
  int id = 0;
  std::vector<ObjectSample> samples;  // time ordered
};

struct BodyTruth {
  int id = 0;
  std::string name;
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  Trajectory poses;  // world_from_body (body origin = box centre), time ordered
};

struct ObjectMetricsOptions {
  int64_t max_time_diff_us = 20000;  // estimate / truth association in time (µs)
  double max_match_distance =
      5.0;              // largest mean distance of an estimate from its body (m, truth units)
  int min_samples = 3;  // fewest common samples for a match (count)
  int64_t horizon_us = 1000000;          // predicted-volume horizon evaluated (µs)
  int64_t horizon_tolerance_us = 50000;  // volumes within this of the horizon count (µs)
  int64_t settle_us = 2000000;  // relative errors are scored from this long after the first sample (µs)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(max_time_diff_us, 0);
    MBSLAM_CHECK_OPTION_GT(max_match_distance, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_samples, 1);
    MBSLAM_CHECK_OPTION_GE(horizon_us, 0);
    MBSLAM_CHECK_OPTION_GE(horizon_tolerance_us, 0);
    MBSLAM_CHECK_OPTION_GE(settle_us, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("max_time_diff_us", &max_time_diff_us, "estimate / truth association in time (µs)");
    v("max_match_distance", &max_match_distance,
      "largest mean distance of an estimate from its body (m)");
    v("min_samples", &min_samples, "fewest common samples for a match (count)");
    v("horizon_us", &horizon_us, "predicted-volume horizon evaluated (µs)");
    v("horizon_tolerance_us", &horizon_tolerance_us,
      "volumes within this of the horizon count (µs)");
    v("settle_us", &settle_us, "relative errors scored from this long after the first sample (µs)");
  }
};

struct ObjectResult {
  int est_id = 0;
  int gt_id = 0;
  std::string gt_name;
  int num_samples = 0;
  ErrorStats position_error;          // without scale alignment (m)
  ErrorStats position_error_scaled;   // with the best scale about the camera (m)
  double best_scale = 1.0;            // s of p(s) = c + s (p - c)
  double relative_scale_error = 0.0;  // |best_scale - 1|
  ErrorStats depth_error;             // |depth - true depth| (m)
  std::vector<std::pair<int64_t, double>> depth_error_over_time;  // (utime, signed error m)
  // Position error / range (true camera-to-object distance), each sample from settle_us
  // after the object's first sample on: the filter has had that long to converge.
  int settled_samples = 0;
  double rel_error_settled_mean = 0.0;
  double rel_error_settled_median = 0.0;
  double rel_error_at_settle = -1.0;  // the first sample at or after settle_us (< 0: none)
  int volumes_checked = 0;
  int volumes_hit = 0;  // true centre inside the predicted box
  double hit_rate = 0.0;
  // Predicted box volume / true box volume (truth units) of the checked volumes: a hit
  // rate bought with huge boxes shows here. Median; < 0 if none or no true extent.
  double volume_ratio_median = -1.0;
};

struct ObjectsEvaluation {
  std::vector<ObjectResult> objects;  // one per matched estimate
  int num_est_objects = 0;
  int num_gt_bodies = 0;
  int unmatched_est = 0;
  // Of the unmatched estimates: fragments lie within max_match_distance of a true body
  // over min_samples common samples (a body followed by more than one estimate, or a
  // piece of one); short ones have fewer than min_samples samples; phantoms are the rest,
  // long enough and near no body.
  int unmatched_fragments = 0;
  int unmatched_short = 0;
  int unmatched_phantoms = 0;
  int est_samples = 0;        // samples of all estimates
  int unmatched_samples = 0;  // samples of the unmatched estimates
  int fragment_samples = 0;   // of those, of the fragments
  int phantom_samples = 0;    // of those, of the phantoms
  // Predicted volumes of every estimate, matched or not, each sample checked against the
  // true body nearest to it then (within max_match_distance): what a planner sees,
  // fragments included. Samples near no body are not checked (see phantom_samples).
  int volumes_checked_all = 0;
  int volumes_hit_all = 0;
  double hit_rate_all = 0.0;
  // Of those, the volumes that overlap the true box at all (a fragment's box around a
  // part of a body can miss its centre yet cover some of it); needs the true extent.
  int volumes_overlapping_all = 0;
  double overlap_rate_all = 0.0;
  int volumes_checked = 0;
  int volumes_hit = 0;
  double hit_rate = 0.0;  // over all matched objects
  double volume_ratio_median = -1.0;  // over all checked volumes of matched objects (see ObjectResult)
  // Over every settled sample of every matched object (see ObjectResult); < 0 if none.
  int settled_samples = 0;
  double rel_error_settled_mean = -1.0;
};

// World pose of a body at `utime` by interpolation (false if outside its samples or the
// gap is larger than max_gap_us).
bool InterpolatePose(const Trajectory& poses, int64_t utime, int64_t max_gap_us, Rigid3d* pose);

Status EvaluateObjects(const std::map<int, ObjectEstimate>& estimates,
                       const std::map<int, BodyTruth>& truth, const Trajectory& gt_camera,
                       const Sim3d& gt_from_est, const ObjectMetricsOptions& options,
                       ObjectsEvaluation* result);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_OBJECT_METRICS_H_
