#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_GROUND_PLANE_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_GROUND_PLANE_H_

// The ground plane of the static world (thesis sec. 5.1.1), estimated robustly from the
// static map's points: RANSAC over near-horizontal planes (normal within a tilt of an "up"
// hint, e.g. minus the camera's y axis in the world), then least-squares refinement on the
// inliers. It is the reference for the ground-plane and size-bound cues of the
// bearing-only tracker, and MapOutput::ground_plane.

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "common/util/status.h"

namespace mbslam {

// The plane {p : normal . p + offset = 0}; `normal` is a unit vector pointing up, so
// Height(p) is the signed height of p above the ground (world units).
struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0.0;  // (units)

  double Height(const Eigen::Vector3d& point_in_world) const {
    return normal.dot(point_in_world) + offset;
  }
  bool IsValid() const;
  // [normal; offset], the layout of MapOutput::ground_plane.
  Eigen::Vector4d ToVector4() const;
  // Normalises the normal; nullopt for a zero or non-finite vector.
  static std::optional<GroundPlane> FromVector4(const Eigen::Vector4d& plane);
  // Multiplies the world's units by `factor` (the plane itself scales with the world).
  void Rescale(double factor) { offset *= factor; }
};

struct GroundPlaneOptions {
  int max_iterations = 400;        // RANSAC hypotheses (count)
  double inlier_threshold = 0.05;  // point-to-plane distance of an inlier (world units)
  // A band in world units means nothing in an up-to-scale map: when the camera's height
  // above the first fit is small against it, the points within the band include much of
  // what stands on the ground (kerbs, parked cars, walls' feet), all on one side, and the
  // least-squares plane rises above the ground. With the camera's position known
  // (EstimateGroundPlaneAlongTravel), the plane is refitted with the band narrowed to this
  // fraction of the camera's height above the first fit, if that is narrower; the first
  // fit still decides whether there is a ground at all (min_support). 0 = world units only.
  double inlier_threshold_camera_heights = 0.15;
  double max_tilt_deg = 25.0;      // angle between the normal and the up hint at most (deg)
  int min_inliers = 20;            // fewer inliers: no plane (count)
  double min_inlier_ratio = 0.05;  // ... or a smaller share of the points: no plane [0, 1]
  int refine_iterations = 3;       // least-squares refits with re-selected inliers (count)
  // A camera riding at a constant height (a known mounting height, see
  // objects.camera_height_m) travels parallel to the ground: the plane's normal is kept
  // perpendicular to the near-horizontal directions its keyframes spread along by at least
  // this many camera heights (standard deviation of the centres); 0 = never.
  double path_parallel_min_spread = 1.0;
  // Camera at a known height: without a plane along its travel, a plane tilted from the
  // direction of travel by more than this is not the ground (deg).
  double max_travel_tilt_deg = 10.0;
  int64_t seed = 1;                // RANSAC sampling seed (deterministic)
  // Use of the plane by the perception pipeline.
  double min_support = 0.3;  // a plane is used only if this share of the map points lies on it [0, 1]
  // Nothing static lies under the ground: a plane with more than this share of the map's
  // points below it (by more than inlier_threshold) is not the ground. The simulated
  // scenes, CamVid and TartanAir keep at most 1, 0 and 8.5 % of their points under their
  // planes; on uncalibrated hand-held video (DAVIS) the planes fitted to a slope, a wall's
  // foot or a distorted reconstruction held 11-65 % under them, and their depth bound made
  // the far background break the flow bound (camel: 43 % of the features labelled moving).
  // "Below" is measured with the world-unit band of the first fit (inlier_threshold), the
  // one that decides min_support, not the narrowed band of a refit: only points clearly
  // under the plane count, so the noise of a real ground does not.
  double max_below_share = 0.1;
  // Static points lie on or above the ground, so along a ray below the horizon a static
  // point is no deeper than where the ray meets the plane (the depth bound of the flow
  // vector bound, thesis sec. 3.5.2 / 5.1.1), widened by a margin and, near the horizon,
  // by the plane's assumed tilt error.
  double depth_bound_margin = 0.15;             // relative margin on the ground depth (fraction)
  double depth_bound_min_elevation_deg = 3.0;   // rays closer to the horizon get no ground bound (deg)
  double depth_bound_tilt_sigma_deg = 2.0;      // assumed tilt error of the plane (deg)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(max_iterations, 0);
    MBSLAM_CHECK_OPTION_GT(inlier_threshold, 0.0);
    MBSLAM_CHECK_OPTION_GE(inlier_threshold_camera_heights, 0.0);
    MBSLAM_CHECK_OPTION(max_tilt_deg > 0.0 && max_tilt_deg < 90.0);
    MBSLAM_CHECK_OPTION_GE(min_inliers, 3);
    MBSLAM_CHECK_OPTION(min_inlier_ratio >= 0.0 && min_inlier_ratio <= 1.0);
    MBSLAM_CHECK_OPTION_GE(refine_iterations, 0);
    MBSLAM_CHECK_OPTION_GE(path_parallel_min_spread, 0.0);
    MBSLAM_CHECK_OPTION(max_travel_tilt_deg > 0.0 && max_travel_tilt_deg <= 90.0);
    MBSLAM_CHECK_OPTION(min_support >= 0.0 && min_support <= 1.0);
    MBSLAM_CHECK_OPTION(max_below_share >= 0.0 && max_below_share <= 1.0);
    MBSLAM_CHECK_OPTION_GE(depth_bound_margin, 0.0);
    MBSLAM_CHECK_OPTION(depth_bound_min_elevation_deg > 0.0 && depth_bound_min_elevation_deg < 90.0);
    MBSLAM_CHECK_OPTION_GE(depth_bound_tilt_sigma_deg, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("max_iterations", &max_iterations, "RANSAC hypotheses (count)");
    v("inlier_threshold", &inlier_threshold, "point-to-plane distance of an inlier (world units)");
    v("inlier_threshold_camera_heights", &inlier_threshold_camera_heights,
      "camera position known: refit with the band narrowed to this fraction of the camera's height above the first fit, if narrower; 0 = world units only");
    v("max_tilt_deg", &max_tilt_deg, "angle between the normal and the up hint at most (deg)");
    v("min_inliers", &min_inliers, "fewer inliers: no plane (count)");
    v("min_inlier_ratio", &min_inlier_ratio, "smaller inlier share: no plane [0, 1]");
    v("refine_iterations", &refine_iterations, "least-squares refits (count)");
    v("path_parallel_min_spread", &path_parallel_min_spread,
      "camera at a known height: normal perpendicular to keyframe spreads of at least this many camera heights; 0 never");
    v("max_travel_tilt_deg", &max_travel_tilt_deg,
      "camera at a known height, no plane along its travel: a plane tilted more from the travel is not the ground (deg)");
    v("seed", &seed, "RANSAC sampling seed");
    v("min_support", &min_support, "a plane is used only if this share of the map points lies on it [0, 1]");
    v("max_below_share", &max_below_share,
      "a plane with more than this share of the map points below it (beyond inlier_threshold) is not the ground [0, 1]");
    v("depth_bound_margin", &depth_bound_margin,
      "static points lie above the ground: depth bound along rays below the horizon, relative margin (fraction)");
    v("depth_bound_min_elevation_deg", &depth_bound_min_elevation_deg,
      "rays closer to the horizon get no ground depth bound (deg)");
    v("depth_bound_tilt_sigma_deg", &depth_bound_tilt_sigma_deg,
      "assumed tilt error of the plane, widening the ground depth bound near the horizon (deg)");
  }
};

struct GroundPlaneEstimate {
  GroundPlane plane;
  int num_inliers = 0;
  double inlier_ratio = 0.0;  // num_inliers / points [0, 1]
  double rms = 0.0;           // point-to-plane RMS of the inliers (units)
};

// `up_hint`: roughly the world's up direction (need not be unit). Fails on fewer than
// three finite points, a zero up hint, invalid options, or when no plane within the tilt
// limit has enough inliers.
Status EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Vector3d& up_hint, const GroundPlaneOptions& options,
                           GroundPlaneEstimate* estimate);
Status EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Vector3d& up_hint, GroundPlaneEstimate* estimate);
// The same with the normal constrained perpendicular to `in_plane_directions` (directions
// known to lie in the ground plane, e.g. the travel of a camera at a constant height;
// at most two, not parallel; need not be unit).
Status EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Vector3d& up_hint, const GroundPlaneOptions& options,
                           const std::vector<Eigen::Vector3d>& in_plane_directions,
                           GroundPlaneEstimate* estimate);
// Near-horizontal directions (w.r.t. `up`, within max_tilt_deg of the horizontal) along
// which `centres` spread with a standard deviation of at least `min_spread` (units): the
// principal axes of the centres.
std::vector<Eigen::Vector3d> SpreadDirections(const std::vector<Eigen::Vector3d>& centres,
                                              const Eigen::Vector3d& up, double max_tilt_deg,
                                              double min_spread);
// Standard deviation of `centres` along the unit `direction` (units).
double SpreadAlong(const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& direction);

// The ground under a camera that rides at a constant height (a robot's), with the
// pipeline's use rules: the free fit (EstimateGroundPlane) must hold min_support of the
// points and lie below `camera`, and the plane returned at most max_below_share of the
// points under it. When the keyframe centres spread along a near-horizontal direction by at least
// path_parallel_min_spread camera heights above that plane, the plane is refitted to
// contain that direction (a small tilt of a plane fitted to distant points alone would
// make the camera's height above it drift as it moves). When they do not, the free fit
// may be far off: its inlier band is in map units, and when the map's unit is tens of
// camera heights (a low camera looking down a long street) a plane tilted by 20 deg can
// gather more points than the ground. Then the plane fitted along the longest direction
// of travel is taken if the travel is long enough measured against the camera's height
// above that plane. Either refit needs min_support. Without a refit, a free fit tilted
// from the longest direction of travel by more than max_travel_tilt_deg is refused (an
// error: no plane). `centres` empty: the free fit. `camera` is the latest camera centre;
// `along_travel` says which plane was returned. All fits after the first use the inlier
// band narrowed to inlier_threshold_camera_heights of the camera's height above the first
// fit when that is narrower than inlier_threshold.
Status EstimateGroundPlaneAlongTravel(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up_hint,
                                      const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& camera,
                                      const GroundPlaneOptions& options, GroundPlaneEstimate* estimate,
                                      bool* along_travel);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_GROUND_PLANE_H_
