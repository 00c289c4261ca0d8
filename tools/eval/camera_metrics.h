#ifndef MBSLAM_TOOLS_EVAL_CAMERA_METRICS_H_
#define MBSLAM_TOOLS_EVAL_CAMERA_METRICS_H_

// Camera trajectory accuracy: absolute trajectory error (ATE) after SE(3) or Sim(3)
// alignment, relative pose error (RPE), fraction of frames tracked (Sturm et al. 2012
// definitions, times in int64 µs).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/config/options.h"
#include "common/util/status.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

enum class Alignment { kNone, kSE3, kSim3 };
const char* AlignmentName(Alignment a);
bool ParseAlignment(const std::string& text, Alignment* a);

// Summary statistics of a list of errors.
struct ErrorStats {
  int count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;  // standard deviation around the mean
  double min = 0.0;
  double max = 0.0;
  static ErrorStats From(std::vector<double> values);
};

struct AteOptions {
  std::string alignment = "sim3";  // none | se3 | sim3 (sim3 for monocular, up-to-scale estimates)
  int64_t max_time_diff_us = 20000;  // largest time difference of associated poses (µs)
  // A given alignment (gt_from_est), e.g. one computed on another run in the same map:
  // used as it is instead of `alignment` (a relocalised run is scored in the frame of
  // the map it relocalised in). Not an option of the text configuration.
  std::optional<Sim3d> fixed_gt_from_est;

  bool Check() const {
    Alignment a;
    MBSLAM_CHECK_OPTION(ParseAlignment(alignment, &a));
    MBSLAM_CHECK_OPTION_GE(max_time_diff_us, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("alignment", &alignment, "none | se3 | sim3");
    v("max_time_diff_us", &max_time_diff_us, "largest time difference of associated poses (µs)");
  }
};

struct AteResult {
  int num_est = 0;  // poses in the estimate (count)
  int num_gt = 0;   // poses in the ground truth (count)
  std::vector<AssociatedPair> pairs;
  Sim3d gt_from_est;           // the alignment applied to the estimate
  ErrorStats translation;      // |t_gt - t_aligned_est| (m, ground-truth units)
  ErrorStats rotation_deg;     // angle of R_gt^T R_aligned_est (deg)
  std::vector<double> errors;  // translation error per pair (m)
  Trajectory est_aligned;      // aligned estimate poses, one per pair
  bool orientation_aligned = false;  // collinear path: rotation from the camera orientations
};

// Associates by time, aligns (Umeyama on the camera centres) and measures.
Status ComputeAte(const Trajectory& est, const Trajectory& gt, const AteOptions& options,
                  AteResult* result);

struct RpeOptions {
  int delta_frames = 1;    // compare poses this many associated pairs apart (count) ...
  int64_t delta_us = 0;    // ... or, if > 0, this far apart in time (µs)
  double est_scale = 1.0;  // multiplies the estimate's translations (e.g. the Sim(3) scale)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(delta_frames, 1);
    MBSLAM_CHECK_OPTION_GE(delta_us, 0);
    MBSLAM_CHECK_OPTION_GT(est_scale, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("delta_frames", &delta_frames, "compare poses this many associated pairs apart (count)");
    v("delta_us", &delta_us, "or, if > 0, this far apart in time (µs)");
    v("est_scale", &est_scale, "multiplies the estimate's translations");
  }
};

struct RpeResult {
  ErrorStats translation;   // |t of E| (m per delta)
  ErrorStats rotation_deg;  // angle of E (deg per delta)
};

// E_ij = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j), over associated pairs i, j.
Status ComputeRpe(const Trajectory& est, const Trajectory& gt,
                  const std::vector<AssociatedPair>& pairs, const RpeOptions& options,
                  RpeResult* result);

// Fraction of ground-truth frames with an associated tracked estimate.
double FractionTracked(const Trajectory& tracked_est, const Trajectory& gt,
                       int64_t max_time_diff_us);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_CAMERA_METRICS_H_
