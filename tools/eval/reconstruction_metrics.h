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
//   shape after a translation: the same points, shifted by the translation that brings
//     them closest to that surface. The trajectory's similarity carries its own error
//     onto the points through a lever arm: an error of a tenth of a degree in the
//     orientations that fix its rotation shifts the points, 6-7 m from the camera path,
//     by about a centimetre, while it turns them by only that tenth of a degree. Only the
//     shift is refitted, so that the fit cannot absorb the shape's own errors (a
//     rotation about a face's normal or a tilt); the scale stays the trajectory's (with a
//     free scale the points would shrink onto one face).
// Each reconstruction is matched to the body it fits best.

#include <cstddef>
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
  // After the points' own translation to the surface (scale and rotation kept); not
  // fitted (the fields repeat the unfitted figures) with fewer than 4 points.
  bool shape_translated = false;
  double shape_translated_rmse_m = 0.0;
  double shape_translated_err_rel = 0.0;         // shape_translated_rmse_m / size_m
  double shape_translated_err_rel_median = 0.0;
  double translation_fit_m = 0.0;                // length of that translation
};

// Distance of p to the surface of the box of full size `extent` centred at the origin.
double BoxSurfaceDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& extent);

// Signed distance of p to the surface of that box: negative inside.
double BoxSignedDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& extent);

// Fewer points than this are not shifted (three parameters fit any three).
inline constexpr size_t kMinShiftedPoints = 4;

// The translation (in the box's frame) that brings `points` closest to the surface of
// the box of full size `extent` centred at the origin, in the least-squares sense
// (Levenberg-Marquardt from zero); the points are shifted by it. Fewer than
// kMinShiftedPoints are left as they are, and zero is returned.
Eigen::Vector3d FitTranslationToBoxSurface(const Eigen::Vector3d& extent, std::vector<Eigen::Vector3d>* points);

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
