#ifndef MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_DENSE_RAYS_H_
#define MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_DENSE_RAYS_H_

// Denser range rays for the occupancy map from a keyframe's sparse static points,
// geometry only. The static map points seen in a keyframe are projected into it and
// triangulated in the image (2D Delaunay, cv::Subdiv2D); each triangle is taken as a
// piece of a plane, and extra ray end points are sampled inside it at the depth that
// plane has there (inverse depth is affine in the image for a plane, so it is
// interpolated linearly). The samples are spaced about `sample_spacing_voxels` voxels
// apart at their depth, so that they cover the surface voxel by voxel without wasting
// rays.
//
// A Delaunay triangle also spans what is not one surface. Rejected:
//   * triangles with an image edge longer than `max_edge_px` (sparse areas, where the
//     plane assumption is a guess);
//   * triangles whose farthest vertex is more than `max_depth_ratio` times as far as the
//     nearest (a depth discontinuity: foreground against background);
//   * triangles seen at more than `max_incidence_deg` from their normal (a surface
//     nearly along the viewing rays: typically the bridge across a discontinuity);
//   * triangles touching a moving object's image hull (grown by `hull_margin_px`), and
//     single samples inside one: moving objects are never put in the static map.
// And points whose depth is too uncertain to place a surface within a voxel or so
// (`max_depth_sigma_voxels`: a point triangulated with little parallax, typically far
// away) are not used as vertices: interpolating between them would spread their error
// over the whole triangle. The caller gives each point's depth uncertainty
// (TriangulationDepthSigma).
//
// Evidence. These end points are interpolated, not measured: OccupancyMap gives their
// voxels a weaker hit (`prob_hit`) than a triangulated point's, and each keyframe
// updates each voxel at most once (one scan, OctoMap's insertPointCloud semantics), so
// a surface seen from many keyframes gains confidence keyframe by keyframe, as a depth
// camera's would, rather than once per sample.
//
//   DenseRayInput in;  in.cam_from_world = ...; in.points_in_world = ...; in.focal_px = ...
//   in.voxel = map.resolution();
//   std::vector<Eigen::Vector3d> samples = DensifyKeyframe(in, options.dense, &stats);
//
// The algorithm layer: no LCM, no threads.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct DenseRayOptions {
  // Cast interpolated rays inside the triangulated keyframe points (bool).
  bool enabled = true;
  // Fewest static points seen in the keyframe to triangulate (count).
  int min_points = 8;
  // Triangles with a longer image edge are skipped (px at the keyframe's focal length).
  double max_edge_px = 90.0;
  // Triangles whose farthest vertex is farther than this multiple of the nearest are
  // skipped: a depth discontinuity (ratio, > 1).
  double max_depth_ratio = 1.6;
  // Triangles whose normal is farther than this from the viewing ray are skipped (deg).
  double max_incidence_deg = 85.0;
  // Samples this many voxels apart at their depth (voxels).
  double sample_spacing_voxels = 1.0;
  // Samples at least this far apart in the image (px).
  double min_spacing_px = 2.0;
  // At most this many samples per keyframe; beyond it the spacing grows (count).
  int max_samples = 6000;
  // Moving objects' hulls are grown by this before triangles and samples touching them
  // are skipped (px).
  double hull_margin_px = 6.0;
  // Nearest vertex depth used (map units): points closer than this are left out.
  double min_depth = 1e-6;
  // Points whose depth uncertainty exceeds this many voxels are not triangulated
  // (voxels); 0 = no limit.
  double max_depth_sigma_voxels = 2.5;
  // Bearing noise of a point's observations, for its depth uncertainty (px).
  double bearing_sigma_px = 0.5;
  // Occupancy probability an interpolated end point gives its voxel (probability, >
  // 0.5, at most occupancy.prob_hit).
  double prob_hit = 0.6;
  // Interpolated rays also give free space along their way (bool). Off by default: on
  // sim-static it changed the precision by < 0.01, cost 0.04 of recall (surfaces seen
  // at grazing angles are eroded) and five times the update time; the measured rays
  // give free space in any case.
  bool free_space = false;

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(min_points, 3);
    MBSLAM_CHECK_OPTION_GT(max_edge_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_depth_ratio, 1.0);
    MBSLAM_CHECK_OPTION_GT(max_incidence_deg, 0.0);
    MBSLAM_CHECK_OPTION_LE(max_incidence_deg, 90.0);
    MBSLAM_CHECK_OPTION_GT(sample_spacing_voxels, 0.0);
    MBSLAM_CHECK_OPTION_GT(min_spacing_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_samples, 0);
    MBSLAM_CHECK_OPTION_GE(hull_margin_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(min_depth, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_depth_sigma_voxels, 0.0);
    MBSLAM_CHECK_OPTION_GT(bearing_sigma_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(prob_hit, 0.5);
    MBSLAM_CHECK_OPTION_LT(prob_hit, 1.0);
    return true;
  }

  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("enabled", &enabled,
      "cast interpolated rays inside the image triangulation of each keyframe's static points");
    v("min_points", &min_points, "fewest static points seen in a keyframe to triangulate (count)");
    v("max_edge_px", &max_edge_px, "triangles with a longer image edge are skipped (px)");
    v("max_depth_ratio", &max_depth_ratio,
      "triangles whose farthest vertex is farther than this multiple of the nearest are skipped: a "
      "depth discontinuity (ratio)");
    v("max_incidence_deg", &max_incidence_deg,
      "triangles whose normal is farther than this from the viewing ray are skipped (deg)");
    v("sample_spacing_voxels", &sample_spacing_voxels,
      "interpolated samples this many voxels apart at their depth (voxels)");
    v("min_spacing_px", &min_spacing_px, "interpolated samples at least this far apart in the image (px)");
    v("max_samples", &max_samples,
      "at most this many interpolated samples per keyframe; beyond it the spacing grows (count)");
    v("hull_margin_px", &hull_margin_px,
      "moving objects' hulls grown by this before triangles and samples touching them are skipped (px)");
    v("min_depth", &min_depth, "points nearer than this are not triangulated (map units)");
    v("max_depth_sigma_voxels", &max_depth_sigma_voxels,
      "points whose depth uncertainty exceeds this many voxels are not triangulated; 0 = no limit "
      "(voxels)");
    v("bearing_sigma_px", &bearing_sigma_px,
      "bearing noise of a point's observations, for its depth uncertainty (px)");
    v("prob_hit", &prob_hit,
      "occupancy probability an interpolated end point gives its voxel, at most occupancy.prob_hit "
      "(probability)");
    v("free_space", &free_space, "interpolated rays also give free space along their way (bool)");
  }
};

struct DenseRayInput {
  Rigid3d cam_from_world;                      // the keyframe's pose
  std::vector<Eigen::Vector3d> points_in_world;  // static map points seen in the keyframe (map units)
  // Their depth uncertainty (map units, TriangulationDepthSigma); empty = unknown (no
  // point is left out for it).
  std::vector<double> depth_sigma;
  double focal_px = 0.0;                       // focal length (px): image distances from normalised ones
  double voxel = 0.0;                          // voxel edge of the map (map units)
  // Moving objects' image outlines in normalised coordinates (x/z, y/z), convex.
  std::vector<std::vector<Eigen::Vector2d>> moving_hulls_xy;
};

// What one DensifyKeyframe call did (counts).
struct DenseRayStats {
  int points = 0;               // points triangulated
  int uncertain = 0;            // points left out: depth uncertainty above the limit
  int triangles = 0;            // Delaunay triangles between them
  int triangles_used = 0;       // sampled
  int rejected_edge = 0;        // longer than max_edge_px
  int rejected_depth = 0;       // depth ratio above max_depth_ratio
  int rejected_incidence = 0;   // seen at more than max_incidence_deg
  int rejected_moving = 0;      // touching a moving hull
  int samples = 0;              // end points returned
  int samples_in_hulls = 0;     // samples dropped inside a moving hull
  double spacing_scale = 1.0;   // > 1 when max_samples made the spacing coarser
};

// Depth uncertainty (map units) of a point triangulated from views at `centers` (world
// frame, map units), along the ray from `view_center`: the widest parallax angle theta
// between that ray and the ray from any of the centres gives sigma = depth *
// bearing_sigma / sin(theta) (two-view triangulation, small angles). Infinite when no
// centre gives any parallax.
double TriangulationDepthSigma(const Eigen::Vector3d& point, const Eigen::Vector3d& view_center,
                               const std::vector<Eigen::Vector3d>& centers, double bearing_sigma_rad);

// Interpolated end points (world frame, map units) for the keyframe; empty when fewer
// than min_points usable points, or options.enabled is false, or input.voxel <= 0.
std::vector<Eigen::Vector3d> DensifyKeyframe(const DenseRayInput& input, const DenseRayOptions& options,
                                             DenseRayStats* stats = nullptr);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_DENSE_RAYS_H_
