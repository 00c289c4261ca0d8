#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_BUNDLE_ADJUSTER_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_BUNDLE_ADJUSTER_H_

// Ceres bundle adjustment over a snapshot of part of a map, so that it can run in a
// back-end thread while the front end keeps tracking; the result is merged back.
// Huber loss on pixel reprojection errors, explicit Schur ordering (points first),
// optional odometry translation priors (metric scale), optional relative rotation
// priors (an object's SLAM: the object barely turns while the camera's own rotation is
// known), and the solver summary decides whether the result is used.

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/slam/map.h"

namespace mbslam {

struct BundleAdjustmentOptions {
  int window_keyframes = 7;      // keyframes optimised in a local BA (count)
  int max_iterations = 15;       // solver iterations (count)
  double max_seconds = 0.2;      // solver time limit (s)
  // Live, the solver stops at max_seconds of wall time; a lockstep replay turns this off
  // (PerceptionOptions::core) so that its result does not depend on how loaded the
  // machine is: max_iterations alone bounds it there.
  bool time_limited = true;
  double huber_px = 2.0;         // Huber threshold (px)
  double outlier_px = 4.0;       // observations above this after the BA are removed (px)
  int global_max_keyframes = 40; // a map up to this size gets a global BA after initialisation (count)
  // A global BA asked for (SlamSystem::RequestGlobalBundleAdjustment) runs in the back-end
  // over the whole map, however large, with these bounds instead.
  int requested_max_iterations = 50;   // solver iterations (count)
  double requested_max_seconds = 5.0;  // solver time limit (s)
  double odometry_sigma_per_m = 0.02;  // odometry translation prior: noise per metre (m/m)
  double odometry_sigma_floor_m = 0.005;  // ... plus this floor (m)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(window_keyframes, 2);
    MBSLAM_CHECK_OPTION_GT(max_iterations, 0);
    MBSLAM_CHECK_OPTION_GT(max_seconds, 0.0);
    MBSLAM_CHECK_OPTION_GT(huber_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(outlier_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(global_max_keyframes, 2);
    MBSLAM_CHECK_OPTION_GT(requested_max_iterations, 0);
    MBSLAM_CHECK_OPTION_GT(requested_max_seconds, 0.0);
    MBSLAM_CHECK_OPTION_GT(odometry_sigma_per_m, 0.0);
    MBSLAM_CHECK_OPTION_GT(odometry_sigma_floor_m, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("window_keyframes", &window_keyframes, "keyframes optimised by local BA (count)");
    v("max_iterations", &max_iterations, "solver iterations (count)");
    v("max_seconds", &max_seconds, "solver time limit (s)");
    v("time_limited", &time_limited, "stop at max_seconds (lockstep replays: off, deterministic)");
    v("huber_px", &huber_px, "Huber threshold (px)");
    v("outlier_px", &outlier_px, "observations above this after BA are removed (px)");
    v("global_max_keyframes", &global_max_keyframes, "maps up to this size get a global BA (count)");
    v("requested_max_iterations", &requested_max_iterations,
      "solver iterations of a global BA asked for (SNAPSHOT_REQUEST WHAT_GLOBAL_BA) (count)");
    v("requested_max_seconds", &requested_max_seconds,
      "solver time limit of a global BA asked for (s)");
    v("odometry_sigma_per_m", &odometry_sigma_per_m, "odometry prior noise per metre (m/m)");
    v("odometry_sigma_floor_m", &odometry_sigma_floor_m, "odometry prior noise floor (m)");
  }
};

// The part of a map a bundle adjustment works on, copied out of it.
struct BaProblem {
  struct Pose {
    Rigid3d cam_from_world;
    bool fixed = false;
    bool has_odometry = false;
    Rigid3d odom_from_cam;
    int64_t utime = 0;
    std::optional<CameraRotationPrior> rotation_prior;
  };
  std::map<int64_t, Pose> keyframes;
  std::map<int64_t, Eigen::Vector3d> points;
  struct Obs {
    int64_t keyframe_id;
    int64_t point_id;
    Eigen::Vector2d xy;
  };
  std::vector<Obs> observations;
  double focal_px = 1.0;
  bool use_odometry = false;
  // Relative rotation priors between consecutive keyframes that carry a rotation prior of
  // the same reference: R_b R_a^T = P_b P_a^T within sigma = floor + rate * |t_b - t_a|
  // (the body's angular speed in the reference frame); both 0 = none.
  double rotation_prior_floor_rad = 0.0;
  double rotation_prior_rad_per_s = 0.0;
};

struct BaSummary {
  bool usable = false;
  int iterations = 0;
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int residuals = 0;
  double seconds = 0.0;
};

// The rotation prior's sigma between two images `dt_us` apart: floor + rate * |dt| (rad).
double RotationPriorSigma(double floor_rad, double rad_per_s, int64_t dt_us);

// Copies the local window (the last `window` keyframes, the points they observe, and
// the other keyframes observing those points, held fixed). `global` takes all.
BaProblem ExtractBaProblem(const Map& map, int window, bool global, double focal_px, bool use_odometry);

BaSummary SolveBa(BaProblem* problem, const BundleAdjustmentOptions& options);

// Writes the adjusted poses and points back (points removed meanwhile are skipped),
// and removes observations that are still outliers; points left with fewer than two
// observations are deleted. Returns the number of removed observations.
int ApplyBaResult(const BaProblem& problem, const BundleAdjustmentOptions& options, Map* map);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_BUNDLE_ADJUSTER_H_
