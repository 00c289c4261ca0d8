#ifndef MBSLAM_TOOLS_EVAL_RECONSTRUCTION_METRICS_H_
#define MBSLAM_TOOLS_EVAL_RECONSTRUCTION_METRICS_H_

// Scoring a moving object's own reconstruction (its SLAM, in its own frame and scale)
// against the simulator's truth (issue: per-body SLAM, "a reconstructed moving object"):
//   camera-relative trajectory: the camera in the object's map (obj_from_cam per image)
//     against the true body_from_cam, after the best similarity (rotation from the
//     orientations, which a straight relative path leaves undetermined otherwise; scale
//     and translation by least squares); RMSE over the path length and the mean range;
//   shape: the object's points through that similarity, distance to the surface of the
//     body's true box (origin at its centre, extent along body x y z), over its size
//     (the largest extent);
//   shape after a rigid fit: the same points, moved by the rotation and translation
//     (scale kept) that bring them closest to that surface. The trajectory's similarity
//     carries its own error onto the points through a lever arm: an error of a tenth of a
//     degree in the orientations that fix its rotation moves the points, 6-7 m from the
//     camera path, by about a centimetre, which is not an error of the shape itself. The
//     scale stays the trajectory's: with a free scale the points would shrink onto one face.
// Each reconstruction is matched to the body it fits best.

#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/util/status.h"
#include "tools/eval/object_metrics.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

struct ReconstructionEstimate {
  int object_id = 0;
  int64_t map_id = 0;
  Trajectory obj_from_cam;              // the camera in the object's map (its units)
  std::vector<Eigen::Vector3d> points;  // object frame (its units)
};

struct ReconstructionResult {
  int object_id = 0;
  int64_t map_id = 0;
  int gt_id = 0;
  std::string gt_name;
  int samples = 0;
  double scale = 0.0;                 // truth metres per object map unit
  double path_length_m = 0.0;         // camera path relative to the body (truth)
  double mean_range_m = 0.0;          // mean camera-body distance (truth)
  double trajectory_rmse_m = 0.0;
  double trajectory_err_rel_path = 0.0;
  double trajectory_err_rel_range = 0.0;
  int num_points = 0;
  double size_m = 0.0;                // the body's largest extent
  double shape_rmse_m = 0.0;          // point-to-box-surface distance
  double shape_median_m = 0.0;
  double shape_err_rel = 0.0;         // shape_rmse_m / size_m
  double shape_err_rel_median = 0.0;  // shape_median_m / size_m
  double share_within_2pct = 0.0;     // points within 2 % of the size of the surface
  // After the rigid fit of the points to the surface (scale kept).
  double shape_rigid_rmse_m = 0.0;
  double shape_rigid_err_rel = 0.0;          // shape_rigid_rmse_m / size_m
  double shape_rigid_err_rel_median = 0.0;
  double rigid_fit_rotation_deg = 0.0;       // how far the fit moved the points: rotation
  double rigid_fit_translation_m = 0.0;      // ... and translation at their centroid
};

// Distance of p to the surface of the box of full size `extent` centred at the origin.
double BoxSurfaceDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& extent);

// Signed distance of p to the surface of that box: negative inside.
double BoxSignedDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& extent);

// The rigid motion (applied in the box's frame) that brings `points` closest to the
// surface of the box of full size `extent` centred at the origin, in the least-squares
// sense (Levenberg-Marquardt from the identity); the points are replaced by the moved ones.
// Fewer than 7 points are left as they are (six parameters fit almost any six points).
Rigid3d FitPointsToBoxSurface(const Eigen::Vector3d& extent, std::vector<Eigen::Vector3d>* points);

// Matches `est` to the body of `truth` whose true camera-relative trajectory it fits best
// (lowest trajectory error over the mean range); needs >= min_samples common images.
Status EvaluateReconstruction(const ReconstructionEstimate& est, const std::map<int, BodyTruth>& truth,
                              const Trajectory& gt_world_from_cam, int64_t max_time_diff_us, int min_samples,
                              ReconstructionResult* result);

// Reads DIR/<object>_<map>.tum and DIR/<object>_<map>.xyz as the service writes them.
Status ReadReconstructions(const std::string& dir, std::vector<ReconstructionEstimate>* out);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_RECONSTRUCTION_METRICS_H_
