#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_RELATIVE_MOTION_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_RELATIVE_MOTION_H_

// The motion of the camera relative to one body between a reference image r and the
// current image n, with its uncertainty: what the constraints of thesis ch. 3 are
// evaluated with. It comes from the body's SLAM, from odometry (sec. 3.8), or from a
// robust two-view estimate on the body's own tracks.

#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/config/options.h"
#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct RelativeMotion {
  Rigid3d cam_n_from_cam_r;                 // x_in_cam_n = cam_n_from_cam_r * x_in_cam_r
  Matrix6d covariance = Matrix6d::Zero();   // left perturbation [t; r] of cam_n_from_cam_r
  bool translation_known = true;            // false: pure rotation (too little parallax)
  bool scale_known = false;                 // translation in the units of the depth bounds
  enum class Source { kSlam, kOdometry, kTwoView } source = Source::kTwoView;
  // Fitted to the tracks' epipolar geometry already (SLAM's epipolar-assisted poses): the
  // segmenter does not check it against its own two-view estimate.
  bool fitted_to_tracks = false;
};

// A weighted sample of the motion distribution (sigma points of the covariance).
struct MotionSample {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Matrix3d E = Eigen::Matrix3d::Zero();  // [t]x R
  double weight = 1.0;
};

// Sigma points of the motion: the mean plus +-sqrt(n + kappa) standard deviations along
// each principal direction of the covariance (directions with negligible variance are
// skipped). Weights sum to one.
std::vector<MotionSample> MotionSigmaPoints(const RelativeMotion& motion, double kappa = 1.0);

struct TwoViewOptions {
  double sigma_px = 0.8;           // feature position noise (px)
  double ransac_threshold_px = 1.5;  // inlier threshold on the epipolar distance (px)
  double ransac_confidence = 0.999;  // RANSAC confidence
  double min_parallax_px = 1.0;    // median rotation-compensated flow below this = pure rotation, no essential fit (px)
  int min_points = 12;             // fewer correspondences: no estimate (count)
  int ransac_max_iterations = 1000;  // RANSAC iterations at most (count; bounds the cost at low inlier ratios)
  int ransac_min_iterations = 0;     // mbslam backend: samples at least, whatever the adaptive rule says (count)
  bool cheirality_refine = true;   // refine a motion that puts too many inliers behind the cameras with them held in front
  double front_margin_px = 2.0;    // flow against the direction of positive depth tolerated as noise (px)
  double max_behind_share = 0.5;   // inliers behind (beyond the margin) above this share trigger the refinement
  double front_keep_ratio = 0.9;   // the refined motion is kept if it keeps this share of the inliers (and fewer behind)
  // A heading given by the caller (the translation direction of the previous motion: a
  // camera's heading changes little between images) is refined on the correspondences
  // and preferred to the RANSAC essential matrix when it explains this share of its
  // inliers: with sliding, edge-like tracks a wrong direction can win the RANSAC by a few
  // inliers (0 = off).
  double heading_keep_ratio = 0.9;
  // The essential matrix RANSAC: "mbslam" (the project's five-point solver, about seven
  // times fewer instructions per sample) or "opencv" (cv::findEssentialMat).
  std::string essential_backend = "mbslam";
  // With the mbslam backend: the model with the lowest sum of capped squared Sampson
  // distances wins, not the one with the most inliers (on TartanAir the ATE varied less
  // with the sampler's seed: 0.93-1.03 % against 1.00-1.30 % over four / three seeds).
  bool ransac_msac = true;
  // With the mbslam backend: the sampler's seed (each call starts from it, so a result
  // depends only on its input). Another seed is another draw: the evaluations' spread
  // over seeds is how much of a change is the draw's. (The segmentation's options: SLAM's
  // epipolar-assisted pose keeps the default, its initialisation uses OpenCV's RANSAC.)
  int64_t ransac_seed = 0x5eed;

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(sigma_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(ransac_threshold_px, 0.0);
    MBSLAM_CHECK_OPTION(ransac_confidence > 0.0 && ransac_confidence < 1.0);
    MBSLAM_CHECK_OPTION_GE(min_parallax_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_points, 8);
    MBSLAM_CHECK_OPTION_GE(ransac_max_iterations, 1);
    MBSLAM_CHECK_OPTION_GE(ransac_min_iterations, 0);
    MBSLAM_CHECK_OPTION_GE(front_margin_px, 0.0);
    MBSLAM_CHECK_OPTION(max_behind_share >= 0.0 && max_behind_share <= 1.0);
    MBSLAM_CHECK_OPTION(front_keep_ratio >= 0.0 && front_keep_ratio <= 1.0);
    MBSLAM_CHECK_OPTION(heading_keep_ratio >= 0.0 && heading_keep_ratio <= 1.0);
    MBSLAM_CHECK_OPTION(essential_backend == "mbslam" || essential_backend == "opencv");
    MBSLAM_CHECK_OPTION(ransac_seed >= 0 && ransac_seed <= 0xffffffffll);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("sigma_px", &sigma_px, "feature position noise (px)");
    v("ransac_threshold_px", &ransac_threshold_px, "RANSAC inlier threshold, epipolar distance (px)");
    v("ransac_confidence", &ransac_confidence, "RANSAC confidence");
    v("min_parallax_px", &min_parallax_px, "median rotation-compensated flow below this = pure rotation (px)");
    v("min_points", &min_points, "fewest correspondences for an estimate (count)");
    v("ransac_max_iterations", &ransac_max_iterations, "RANSAC iterations at most (count)");
    v("ransac_min_iterations", &ransac_min_iterations,
      "mbslam backend: RANSAC samples at least, whatever the adaptive rule says (count)");
    v("cheirality_refine", &cheirality_refine,
      "refine a motion that puts too many inliers behind the cameras with them held in front");
    v("front_margin_px", &front_margin_px, "flow against the direction of positive depth tolerated as noise (px)");
    v("max_behind_share", &max_behind_share, "inliers behind (beyond the margin) above this share trigger the refinement");
    v("front_keep_ratio", &front_keep_ratio, "the refined motion is kept if it keeps this share of the inliers (and fewer behind)");
    v("heading_keep_ratio", &heading_keep_ratio,
      "a heading given by the caller (the previous motion's), refined, is preferred when it explains this share of "
      "the essential matrix's inliers (0 = off)");
    v("essential_backend", &essential_backend,
      "essential matrix RANSAC: mbslam (the project's five-point solver, faster) or opencv (cv::findEssentialMat)");
    v("ransac_msac", &ransac_msac,
      "mbslam backend: the lowest sum of capped squared errors wins (MSAC), not the most inliers");
    v("ransac_seed", &ransac_seed, "mbslam backend: the sampler's seed, the same for every call (another seed, another draw)");
  }
};

// Robust relative motion from normalised correspondences x_r <-> x_n (five-point
// RANSAC, options.essential_backend; pose recovery with cheirality), or a pure rotation when the parallax is too
// small for the translation to be observable. Translation has unit norm. The
// covariance comes from the inliers' epipolar residuals (Gauss-Newton information).
// `heading` (unit, optional): an expected translation direction, tried against the
// RANSAC solution (options.heading_keep_ratio).
Status EstimateRelativeMotion(const std::vector<Eigen::Vector2d>& x_r,
                              const std::vector<Eigen::Vector2d>& x_n, double focal_px,
                              const TwoViewOptions& options, RelativeMotion* motion,
                              std::vector<uint8_t>* inliers, const Eigen::Vector3d* heading = nullptr);

// Signed distance (normalised units) of x_n to the epipolar line E x_r. Inline: it runs
// per track and envelope sample.
inline double EpipolarDistance(const Eigen::Matrix3d& E, const Eigen::Vector2d& x_r,
                               const Eigen::Vector2d& x_n) {
  const Eigen::Vector3d l = E * x_r.homogeneous();
  // sqrt of the sum, not std::hypot: the components are far from overflow, and hypot's
  // care about it doubled this function's cost.
  const double norm = std::sqrt(l.x() * l.x() + l.y() * l.y());
  if (norm < 1e-15) return 0.0;
  return x_n.homogeneous().dot(l) / norm;
}

// EpipolarDistance(E, x_r, x_n) for E = [t]x R, and its derivative w.r.t. a left
// perturbation of the motion, Exp([v; w]) * (R, t) (the twist order of rigid3.h). To
// first order the perturbation moves E by [v]x R + [w]x E, so with a = R x_r and
// l = E x_r the line moves by v x a + w x l, and d(distance) = [a x g; l x g] . [v; w],
// g = (x_n - (distance / |l_xy|) l_xy) / |l_xy| (homogeneous x_n, l_xy = (l_x, l_y, 0)).
// Zero, with a zero derivative, for a degenerate line, as EpipolarDistance.
inline double EpipolarDistanceAndJacobian(const Eigen::Matrix3d& R, const Eigen::Matrix3d& E,
                                          const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n,
                                          Eigen::Matrix<double, 1, 6>* J) {
  const Eigen::Vector3d xr = x_r.homogeneous();
  const Eigen::Vector3d l = E * xr;
  const double norm = std::sqrt(l.x() * l.x() + l.y() * l.y());
  if (norm < 1e-15) {
    J->setZero();
    return 0.0;
  }
  const Eigen::Vector3d xn = x_n.homogeneous();
  const double d = xn.dot(l) / norm;
  const Eigen::Vector3d g = (xn - (d / norm) * Eigen::Vector3d(l.x(), l.y(), 0.0)) / norm;
  J->head<3>() = (R * xr).cross(g).transpose();
  J->tail<3>() = l.cross(g).transpose();
  return d;
}

// Where a static point's image moves under the motion x_n = R x_r + t: it leaves the
// rotated position p = (R x_r) normalised along u = (t_xy - t_z p) / |t_xy - t_z p|, by
// |t_xy - t_z p| / (z' + t_z) for its depth z' after rotation. `flow` is x_n's signed
// displacement along u, so a point in front of both cameras has flow >= 0 (up to noise).
struct DepthFlow {
  bool valid = false;     // false: R x_r behind the camera, or the point on the epipole
  double dir_norm = 0.0;  // |t_xy - t_z p|
  double flow = 0.0;      // (x_n - p) . u (normalised units)
};

// From the rotated position p itself (for callers that have it already).
inline DepthFlow DepthFlowAt(const Eigen::Vector2d& p, const Eigen::Vector3d& t, const Eigen::Vector2d& x_n) {
  DepthFlow out;
  const Eigen::Vector2d dir = t.head<2>() - t.z() * p;
  out.dir_norm = dir.norm();
  if (out.dir_norm < 1e-12) return out;
  out.flow = (x_n - p).dot(dir / out.dir_norm);
  out.valid = true;
  return out;
}

inline DepthFlow DepthFlowOf(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const Eigen::Vector2d& x_r,
                             const Eigen::Vector2d& x_n) {
  const Eigen::Vector3d rx = R * x_r.homogeneous();
  if (rx.z() <= 1e-9) return DepthFlow();
  return DepthFlowAt(rx.hnormalized(), t, x_n);
}

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_RELATIVE_MOTION_H_
