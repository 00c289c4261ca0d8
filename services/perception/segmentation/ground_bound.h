#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_GROUND_BOUND_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_GROUND_BOUND_H_

// The ground plane of one image pair, for the Flow Vector Bound's depth bound before a
// map has one (thesis sec. 3.5.2 with the ground plane cue of sec. 5.1.1).
//
// For a plane n.X = d seen from the reference camera, a point's inverse depth is linear
// in its normalised image position: 1 / z = m . [x y 1] with m = n / d. Under the pair's
// motion (R, t), each static track's inverse depth s follows from its two positions
// (x_n ~ R [x_r; 1] + t s), in the units of t, whatever they are (a two-view estimate's
// unit translation, the map's units): so the plane m comes out in the units of the
// motion, and so does every depth bound taken from it. The plane is fitted by MSAC (with
// a local refit) to the tracks whose inverse depth is precise, and must qualify: below
// the camera, its normal within max_tilt_deg of the reference camera's down axis (+y:
// the image's "down" is the world's, as for the ground plane of the map); its inliers
// spanning a range of depths (near the horizon any steep plane fits a distant facade's
// tracks); few tracks beyond it, imprecise ones included (the static world stands on the
// ground; a slab through a cloud of points, or a wrong plane under far tracks, has many
// beyond). A static point lies on or above the ground, so along a ray that meets the
// ground in front of the camera its depth is at most where the ray meets it: a track
// moving with the camera (a degenerate mover) looks farther away than that, and the flow
// bound catches it.

#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/segmentation/static_likelihood.h"

namespace mbslam {

struct PairGroundOptions {
  bool enabled = true;             // fit the pair's ground plane and bound the depths of rays below it
  bool with_map = false;           // also when the world motion comes with a map's scale and depth bounds (the map has its own ground plane)
  double max_tilt_deg = 30.0;      // normal at most this far from the reference camera's down axis (deg)
  int min_inliers = 20;            // fewer tracks on the plane: no plane (count)
  double min_inlier_share = 0.15;  // of the tracks whose inverse depth is precise enough to fit [0, 1]
  double inlier_sigmas = 3.0;      // inverse-depth residual of an inlier, in its own standard deviations
  double inlier_rel = 0.05;        // ... plus this fraction of the inverse depth (uneven ground)
  double max_rel_sigma = 0.1;      // tracks whose inverse depth is less precise than this are not used (fraction)
  double min_parallax_px = 4.0;    // median parallax of the inliers at least this (px): less tells no depth
  double min_depth_ratio = 2.0;    // the inliers' depths span at least this ratio (the ground runs from near to far; a distant facade does not)
  double max_beyond_share = 0.2;   // tracks farther than the plane along their rays, at most this share of its inliers (the static world lies above the ground)
  int ransac_iterations = 100;     // plane hypotheses (count)
  double depth_bound_margin = 0.15;         // relative margin of the bound (fraction)
  double depth_bound_min_elevation_deg = 3.0;  // rays closer to the plane's horizon get no bound (deg)
  double depth_bound_tilt_sigma_deg = 3.0;  // assumed tilt error of the plane, widening the bound near the horizon (deg)
  int seed = 1;                    // RANSAC sampling seed

  bool Check() const {
    MBSLAM_CHECK_OPTION(max_tilt_deg > 0.0 && max_tilt_deg < 90.0);
    MBSLAM_CHECK_OPTION_GE(min_inliers, 3);
    MBSLAM_CHECK_OPTION(min_inlier_share >= 0.0 && min_inlier_share <= 1.0);
    MBSLAM_CHECK_OPTION_GT(inlier_sigmas, 0.0);
    MBSLAM_CHECK_OPTION_GE(inlier_rel, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_rel_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_parallax_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_depth_ratio, 1.0);
    MBSLAM_CHECK_OPTION_GE(max_beyond_share, 0.0);
    MBSLAM_CHECK_OPTION_GE(ransac_iterations, 1);
    MBSLAM_CHECK_OPTION_GE(depth_bound_margin, 0.0);
    MBSLAM_CHECK_OPTION(depth_bound_min_elevation_deg > 0.0 && depth_bound_min_elevation_deg < 90.0);
    MBSLAM_CHECK_OPTION_GE(depth_bound_tilt_sigma_deg, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("enabled", &enabled, "fit each image pair's ground plane and bound the depth of rays that meet it");
    v("with_map", &with_map, "also when the world motion comes with a map's scale and depth bounds (else only before a map)");
    v("max_tilt_deg", &max_tilt_deg, "normal at most this far from the reference camera's down axis (deg)");
    v("min_inliers", &min_inliers, "fewer tracks on the plane: no plane (count)");
    v("min_inlier_share", &min_inlier_share, "inlier share of the tracks with a precise inverse depth [0, 1]");
    v("inlier_sigmas", &inlier_sigmas, "inverse-depth residual of an inlier (its standard deviations)");
    v("inlier_rel", &inlier_rel, "... plus this fraction of the inverse depth (fraction)");
    v("max_rel_sigma", &max_rel_sigma, "tracks with a less precise inverse depth are not used (fraction)");
    v("min_parallax_px", &min_parallax_px, "median parallax of the inliers at least this (px)");
    v("min_depth_ratio", &min_depth_ratio, "the inliers' depths span at least this ratio (ground runs from near to far)");
    v("max_beyond_share", &max_beyond_share, "tracks beyond the plane along their rays, at most this share of its inliers");
    v("ransac_iterations", &ransac_iterations, "plane hypotheses (count)");
    v("depth_bound_margin", &depth_bound_margin, "relative margin of the depth bound (fraction)");
    v("depth_bound_min_elevation_deg", &depth_bound_min_elevation_deg,
      "rays closer to the plane's horizon get no depth bound (deg)");
    v("depth_bound_tilt_sigma_deg", &depth_bound_tilt_sigma_deg,
      "assumed tilt error of the plane, widening the bound near the horizon (deg)");
    v("seed", &seed, "RANSAC sampling seed");
  }
};

// The plane in the reference camera: inverse depth m . [x y 1], in the motion's units.
struct PairGroundPlane {
  Eigen::Vector3d m = Eigen::Vector3d::Zero();
  int inliers = 0;
  int candidates = 0;             // tracks whose inverse depth was precise enough to fit
  double median_parallax_px = 0;  // of the inliers
};

// A track's inverse depth in the reference camera from its positions x_r, x_n
// (normalised) under cam_n_from_cam_r = (R, t): s with x_n ~ R [x_r; 1] + t s, in the
// units of t, and its standard deviation for a position noise sigma (normalised units).
// False when the pair tells nothing about it (on the epipole, or t = 0).
bool PairInverseDepth(const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n, const Eigen::Matrix3d& R,
                      const Eigen::Vector3d& t, double sigma, double* s, double* s_sigma);

// Fits the plane to the tracks (positions in the reference and current images,
// normalised). nullopt: no plane that qualifies.
std::optional<PairGroundPlane> FitPairGroundPlane(const std::vector<Eigen::Vector2d>& x_r,
                                                  const std::vector<Eigen::Vector2d>& x_n,
                                                  const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                  double focal_px, double sigma_px,
                                                  const PairGroundOptions& options);

// The depth bound of a static point along a ray that meets the ground at depth
// `z_ground`, `elevation_rad` below the ground's horizon: z_ground widened by a relative
// margin and, near the horizon where a small tilt error moves the intersection far, by
// the plane's assumed tilt error (shared with the map's ground plane).
inline double GroundDepthCap(double z_ground, double elevation_rad, double margin, double tilt_sigma_deg) {
  return z_ground * (1.0 + margin + tilt_sigma_deg * M_PI / 180.0 / std::tan(elevation_rad));
}

// `bound` with its z_max capped where the ray x_r meets the plane (with the margins), if
// it does, far enough below the plane's horizon. A z_min beyond the cap is dropped (the
// point it came from is not where a static point can be).
DepthBound CapDepthByGround(const PairGroundPlane& plane, const Eigen::Vector2d& x_r, DepthBound bound,
                            const PairGroundOptions& options);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_GROUND_BOUND_H_
