#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_POSE_ESTIMATOR_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_POSE_ESTIMATOR_H_

// Camera resection against a body's map: EPnP inside RANSAC (also the planar-object
// initialisation of thesis sec. 4.4), refined by motion-only optimisation (robust
// Gauss-Newton on the reprojection errors with the analytic Jacobian), with the pose
// covariance that the segmentation's epipolar envelope needs.

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/config/options.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct PoseEstimatorOptions {
  double ransac_threshold_px = 3.0;  // RANSAC inlier threshold (px)
  int ransac_iterations = 100;       // EPnP RANSAC iterations (count)
  double huber_px = 1.5;             // Huber threshold of the refinement (px)
  double inlier_px = 3.0;            // final inliers: reprojection error below (px)
  int refine_iterations = 10;        // Gauss-Newton iterations (count)
  double sigma_px = 1.0;             // measurement noise for the covariance (px)
  double prior_inlier_ratio = 0.7;   // with a prior pose explaining this share, RANSAC is skipped

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(ransac_threshold_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(ransac_iterations, 0);
    MBSLAM_CHECK_OPTION_GT(huber_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(inlier_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(refine_iterations, 0);
    MBSLAM_CHECK_OPTION_GT(sigma_px, 0.0);
    MBSLAM_CHECK_OPTION(prior_inlier_ratio > 0.0 && prior_inlier_ratio <= 1.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("ransac_threshold_px", &ransac_threshold_px, "EPnP RANSAC inlier threshold (px)");
    v("ransac_iterations", &ransac_iterations, "EPnP RANSAC iterations (count)");
    v("huber_px", &huber_px, "Huber threshold of the motion-only refinement (px)");
    v("inlier_px", &inlier_px, "final inlier threshold (px)");
    v("refine_iterations", &refine_iterations, "Gauss-Newton iterations (count)");
    v("sigma_px", &sigma_px, "measurement noise for the pose covariance (px)");
    v("prior_inlier_ratio", &prior_inlier_ratio, "a prior pose explaining this share skips RANSAC");
  }
};

struct PoseEstimate {
  bool ok = false;
  Rigid3d cam_from_world;
  Matrix6d covariance = Matrix6d::Zero();  // left perturbation [t; r] of cam_from_world
  std::vector<uint8_t> inliers;
  int num_inliers = 0;
  double rms_px = 0.0;                     // RMS reprojection error of the inliers (px)
  bool used_ransac = false;
};

// A soft prior on the rotation of cam_from_world (an object's SLAM: the rotation the
// object's frame would give if it did not turn since its last keyframe), residual
// LogSO3(R * target^T) / sigma_rad, weighted against reprojection errors of sigma_px.
struct PoseRotationPrior {
  Eigen::Quaterniond cam_from_world = Eigen::Quaterniond::Identity();
  double sigma_rad = 1.0;
};

// `prior` (e.g. constant-velocity prediction) is refined directly when it already
// explains most correspondences; otherwise EPnP RANSAC runs first.
PoseEstimate EstimatePose(const std::vector<Eigen::Vector3d>& points_in_world,
                          const std::vector<Eigen::Vector2d>& xy, double focal_px,
                          const std::optional<Rigid3d>& prior, const PoseEstimatorOptions& options,
                          const std::optional<PoseRotationPrior>& rotation_prior = std::nullopt);

// Motion-only refinement (Huber-weighted Gauss-Newton on a left perturbation).
// Returns the refined pose and sets the information matrix J^T W J (in 1/px^2 units
// scaled by focal^2) when `information` is given. A rotation prior enters with weight
// (sigma_px / focal_px)^2 / sigma_rad^2, so that `information` keeps its units.
Rigid3d RefinePose(const Rigid3d& initial, const std::vector<Eigen::Vector3d>& points_in_world,
                   const std::vector<Eigen::Vector2d>& xy, const std::vector<uint8_t>& use,
                   double focal_px, double huber_px, int iterations, Matrix6d* information,
                   const PoseRotationPrior* rotation_prior = nullptr, double sigma_px = 1.0);

// Resection helped by the epipolar geometry, for images whose map correspondences
// are too few (a low-texture wall, tracks that live a few images): the 2D-2D
// correspondences of static tracks with a posed reference image fix the rotation and
// the direction of the motion, the 2D-3D ones (however few) its length, and a weak prior
// on the length of the motion since the reference (the predicted one) holds it when no
// map point is seen. Start: the prediction, and the reference-to-current essential
// matrix (5-point RANSAC) with the predicted length; the one that explains more is refined
// (Huber-weighted Gauss-Newton on a left perturbation, reprojection and epipolar
// distances in normalised units).
struct EpipolarLinks {
  std::vector<Rigid3d> references;       // poses (cam_from_world) of the reference images
  std::vector<int> reference;            // per link: its reference image (index into references)
  std::vector<Eigen::Vector2d> xy_ref;   // normalised coordinates in the reference image
  std::vector<Eigen::Vector2d> xy_cur;   // ... and in the current image
};

struct HybridPoseEstimate {
  PoseEstimate pose;                     // inliers / num_inliers / rms_px: the 2D-3D correspondences
  std::vector<uint8_t> link_inliers;
  int num_link_inliers = 0;
  double link_rms_px = 0.0;              // RMS epipolar distance of the link inliers (px)
};

// `prior`: the predicted pose (a start); `expected_length`: the length of the motion
// since references[length_reference] (map units); `length_sigma_ratio`: the prior's
// standard deviation as a share of it. The essential-matrix start uses the links of
// references[start_reference].
HybridPoseEstimate EstimatePoseWithEpipolar(const std::vector<Eigen::Vector3d>& points_in_world,
                                            const std::vector<Eigen::Vector2d>& xy, const EpipolarLinks& links,
                                            const Rigid3d& prior, int start_reference, int length_reference,
                                            double expected_length, double length_sigma_ratio, double focal_px,
                                            const PoseEstimatorOptions& options);

struct GroundLengthEstimate {
  bool ok = false;      // a length was found (support >= 1)
  double length = 0.0;  // of the motion since length_ref (map units)
  int support = 0;      // links it projects onto their tracks (count)
  int candidates = 0;   // links whose reference ray meets the ground (count)
  // ... the links agreeing at (1 -+ length_step) * length: when these are as many, the
  // views do not tell the length (too little parallax, or no ground in view).
  int support_shorter = 0;
  int support_longer = 0;
};

// The ground plane's cue to the length of a motion whose rotation and direction are
// known (thesis sec. 5.1.1): a link whose reference ray meets the ground `plane`
// ([unit normal pointing up; offset], world) at least min_elevation_rad below the horizon
// is, if it lies on the ground, at that point; the camera centre moves from
// `length_ref`'s (cam_from_world) along the direction of `cam_from_world`'s, and each such
// link gives the length that brings its point closest to its current ray. The length
// returned is the one of these with the least sum of reprojection errors truncated at
// max_error_px (MSAC on the error, not its square): the ground's links agree on it, walls
// and furniture give scattered lengths. Only links with use[i] != 0 count (all if `use`
// is empty). Links of mismatched sizes or references out of range: not ok.
GroundLengthEstimate GroundLengthOfMotion(const EpipolarLinks& links,
                                          const std::vector<uint8_t>& use,
                                          const Eigen::Vector4d& plane, const Rigid3d& length_ref,
                                          const Rigid3d& cam_from_world, double focal_px,
                                          double min_elevation_rad, double max_error_px,
                                          double length_step);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_POSE_ESTIMATOR_H_
