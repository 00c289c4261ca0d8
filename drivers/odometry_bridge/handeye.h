#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_HANDEYE_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_HANDEYE_H_

// Robot-to-camera calibration from paired motions (hand-eye, thesis sec. 3.8.2):
//
//   A_i X = X B_i,   A_i = base motion (odometry), B_i = camera motion, X = base_from_cam.
//
// Rotation: the rotation vectors satisfy a_i = R_X b_i, solved in closed form
// (orthogonal Procrustes / Park-Martin). Translation: (R_Ai - I) t_X - s R_X t_Bi = -t_Ai,
// linear least squares in t_X and the scale s (metres per camera unit), because a
// monocular camera measures its translation only up to scale.
//
// What planar robot motion (every turn about the same axis n, the floor normal) can
// determine: the rotation a_i = R_X b_i then fixes only the direction of n in the
// camera; the remaining angle about n, the translation across n and the scale come
// from the translation equations, which are linear in (t_X across n, s cos, s sin).
// The camera's offset ALONG n (its height above the base origin) never appears in
// them: it is unobservable and is taken from a prior. Straight driving alone fixes
// the angle and the scale but not t_X; turns alone fix t_X across n but not the
// scale; both are needed.

#include <cstdint>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "drivers/common/pose_files.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct MotionPair {
  int64_t utime0 = 0;     // start of the motion (µs)
  int64_t utime1 = 0;     // end of the motion (µs)
  Rigid3d base_motion;    // base0_from_base1 (odometry, metric)
  Rigid3d cam_motion;     // cam0_from_cam1 (camera, translation up to scale)
};

struct HandEyeOptions {
  std::string mode = "auto";          // auto | general | planar
  bool metric_camera = false;         // camera translations are metric (scale fixed to 1)
  double planar_tolerance_deg = 2.0;  // auto: rotation axes within this of their mean = planar motion (deg)
  double min_rotation_deg = 1.0;      // pairs turning less do not enter the rotation estimate (deg)
  double prior_offset_along_axis_m = 0.0;  // planar: the unobservable camera offset along the turn axis (m)

  bool Check() const;
};

struct HandEyeResult {
  Rigid3d base_from_cam;
  double scale = 1.0;            // metres per camera unit (1 with metric_camera)
  bool planar = false;           // solved as planar motion
  Eigen::Vector3d axis_in_base = Eigen::Vector3d::UnitZ();  // planar: the common turn axis
  int pairs = 0;                 // motion pairs used
  int rotating_pairs = 0;        // of those, turning at least min_rotation_deg
  std::vector<double> rotation_residuals_rad;    // per pair: angle of (R_A R_X)^-1 R_X R_B
  std::vector<double> translation_residuals_m;   // per pair: |(R_A - I) t_X + t_A - s R_X t_B|
  double rotation_rms_rad = 0.0;
  double translation_rms_m = 0.0;
  std::string observability;     // what the data determined and what it did not
};

// Solves AX = XB. Fails (with a reason) on data that cannot determine X.
Status SolveHandEye(const std::vector<MotionPair>& pairs, const HandEyeOptions& options,
                    HandEyeResult* result);

struct PairingOptions {
  double min_rotation_deg = 5.0;    // a motion ends once the base turned this much (deg) ...
  double min_translation_m = 0.2;   // ... or moved this far (m)
  double max_duration_s = 5.0;      // motions longer than this are dropped (s)
  double max_gap_s = 0.5;           // largest odometry gap to interpolate across (s)
};

// Pairs the camera trajectory (world_from_cam, any scale) with odometry
// (odom_from_base, interpolated on SE(3) to the camera times): consecutive motions,
// each ending once the base turned or moved enough. `*outside` counts camera poses
// the odometry does not cover.
Status BuildMotionPairs(const std::vector<TimedPose>& world_from_cam,
                        const std::vector<TimedPose>& odom_from_base, const PairingOptions& options,
                        std::vector<MotionPair>* pairs, int* outside);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_HANDEYE_H_
