#ifndef MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCCUPANCY_MAP_H_
#define MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCCUPANCY_MAP_H_

// Occupancy of the static world (thesis sec. 6.3): an OctoMap OcTree built from range
// rays, one from the camera centre to each newly triangulated static point. The voxels
// along a ray get a "free" update, the voxel holding its end point an "occupied" update
// (log-odds, Thrun et al. ch. 9, as OctoMap implements it). Moving objects are never
// inserted: the caller passes static points only.
//
// Interpolated rays. Sparse points cover a surface a point here and there; the caller
// may add interpolated end points (dense_rays.h: samples inside the image triangulation
// of the keyframe's static points). They are reduced to one ray per end voxel, their
// end voxel gets the weaker `dense.prob_hit`, and they give free space along their way
// when `dense.free_space`. Within one InsertRays call every voxel is updated once: a
// hit beats a weak hit beats a miss.
//
//   OccupancyMap map(OccupancyMapOptions(), OccupancyMap::Units::kUpToScale);
//   map.InsertRays(world_from_cam.translation, new_points_in_world,
//                  interpolated_points_in_world);                        // per keyframe
//   map.Rescale(metres_per_unit, OccupancyMap::Units::kMetres);        // once scale is known
//   std::string binary;
//   map.Serialize(&binary);   // occupancy_t.data; readers use ReadOctreeBinary (octree_io.h)
//
// Units. A monocular map is up to scale until odometry fixes it. While the map is up to
// scale the voxel edge (and the range bound) are set from the scene: a fraction of the
// median ray length of the first rays. Until enough rays have arrived to measure that
// depth the rays are only stored and the tree is empty (IsResolutionFixed() is false).
// In metres the options give them directly.
//
// Rescale. When the map's units change (SLAM rescales its world once to metres, or any
// gauge change by a factor), the tree is rebuilt from the stored rays multiplied by the
// factor. The rays are kept for that, bounded by `max_stored_rays` (oldest keyframes
// are forgotten first; a rebuild then lacks their evidence, counted in
// rays_forgotten()).
//
// Bounded memory. A robot that keeps exploring (or a monocular map whose gauge drifts)
// adds voxels without end. When the tree's memory estimate exceeds `max_memory_mb` the
// tree is cropped to the voxels within `keep_half_edge_voxels` (per axis) of the latest
// ray origin, halving that box until the tree is below half the bound, and stored rays
// from outside the box are forgotten. Counted in crops() and voxels_dropped().
//
// Not thread-safe; the algorithm layer has no threads of its own.

#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "common/util/status.h"
#include "services/perception/occupancy/dense_rays.h"

namespace octomap {
class OcTree;
class KeyRay;
}  // namespace octomap

namespace mbslam {

struct OccupancyMapOptions {
  // Voxel edge when the map is in metres (m).
  double resolution_m = 0.1;
  // Rays longer than this contribute free space up to this range only, no occupied end
  // (m); <= 0 means unbounded. Bounding it is what keeps the update cheap.
  double max_range_m = 20.0;
  // Up-to-scale map: voxel edge = this fraction of the median ray length of the first
  // rays (fraction); 0 = use resolution_m as is, in map units.
  double resolution_depth_fraction = 0.02;
  // Up-to-scale map with resolution_depth_fraction > 0: range bound = this multiple of
  // that median ray length (multiple); 0 = max_range_m in map units. (With
  // resolution_depth_fraction = 0 both come from the *_m options, in map units.)
  double max_range_depth_multiple = 4.0;
  // Up-to-scale map: rays collected before their median length fixes the resolution
  // (count).
  int min_rays_for_resolution = 100;
  // Probability of occupancy an end point gives its voxel (probability, > 0.5).
  double prob_hit = 0.7;
  // Probability of occupancy a traversing ray gives each voxel it crosses (probability,
  // < 0.5).
  double prob_miss = 0.4;
  // Lower and upper clamping of the voxel occupancy, so that voxels can change state
  // after long evidence (probability).
  double clamping_min = 0.1192;
  double clamping_max = 0.971;
  // A voxel is occupied above this probability (probability).
  double occupancy_threshold = 0.5;
  // Rays kept to rebuild the tree after a rescale (count); 0 keeps none.
  int max_stored_rays = 1000000;
  // Estimated memory of the tree above which it is cropped around the latest ray origin
  // (MB); 0 = unbounded.
  double max_memory_mb = 64.0;
  // Half edge of the box kept around the latest ray origin by a crop (voxels); halved
  // until the tree is below half of max_memory_mb.
  int keep_half_edge_voxels = 1024;
  // Rays of one insert are first reduced to one per end voxel (faster, slightly
  // different result: OctoMap's discretised update) (bool).
  bool discretize = false;
  // Interpolated rays inside the triangulated keyframe points (dense_rays.h).
  DenseRayOptions dense;

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(resolution_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(resolution_depth_fraction, 0.0);
    MBSLAM_CHECK_OPTION_LE(resolution_depth_fraction, 1.0);
    MBSLAM_CHECK_OPTION_GE(max_range_depth_multiple, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_rays_for_resolution, 1);
    MBSLAM_CHECK_OPTION_GT(prob_hit, 0.5);
    MBSLAM_CHECK_OPTION_LT(prob_hit, 1.0);
    MBSLAM_CHECK_OPTION_GT(prob_miss, 0.0);
    MBSLAM_CHECK_OPTION_LT(prob_miss, 0.5);
    MBSLAM_CHECK_OPTION_GT(clamping_min, 0.0);
    MBSLAM_CHECK_OPTION_LT(clamping_min, occupancy_threshold);
    MBSLAM_CHECK_OPTION_GT(clamping_max, occupancy_threshold);
    MBSLAM_CHECK_OPTION_LT(clamping_max, 1.0);
    MBSLAM_CHECK_OPTION_GT(occupancy_threshold, 0.0);
    MBSLAM_CHECK_OPTION_LT(occupancy_threshold, 1.0);
    MBSLAM_CHECK_OPTION_GE(max_stored_rays, 0);
    MBSLAM_CHECK_OPTION_GE(max_memory_mb, 0.0);
    MBSLAM_CHECK_OPTION_GE(keep_half_edge_voxels, 1);
    MBSLAM_CHECK_OPTION_LE(keep_half_edge_voxels, 32767);
    MBSLAM_CHECK_OPTION_SECTION(dense);
    MBSLAM_CHECK_OPTION_LE(dense.prob_hit, prob_hit);
    return true;
  }

  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("resolution_m", &resolution_m, "voxel edge when the map is in metres (m)");
    v("max_range_m", &max_range_m,
      "rays longer than this give free space up to it only, no occupied end; <= 0 unbounded (m)");
    v("resolution_depth_fraction", &resolution_depth_fraction,
      "up-to-scale map: voxel edge as a fraction of the median ray length of the first rays; "
      "0 = resolution_m in map units (fraction)");
    v("max_range_depth_multiple", &max_range_depth_multiple,
      "up-to-scale map: range bound as a multiple of that median ray length; 0 = max_range_m "
      "in map units (multiple)");
    v("min_rays_for_resolution", &min_rays_for_resolution,
      "up-to-scale map: rays collected before their median length fixes the resolution (count)");
    v("prob_hit", &prob_hit, "occupancy probability an end point gives its voxel (probability)");
    v("prob_miss", &prob_miss,
      "occupancy probability a traversing ray gives each voxel it crosses (probability)");
    v("clamping_min", &clamping_min, "lower clamp of voxel occupancy (probability)");
    v("clamping_max", &clamping_max, "upper clamp of voxel occupancy (probability)");
    v("occupancy_threshold", &occupancy_threshold,
      "a voxel is occupied above this probability (probability)");
    v("max_stored_rays", &max_stored_rays,
      "rays kept to rebuild the tree after a rescale, oldest forgotten first; 0 keeps none "
      "(count)");
    v("max_memory_mb", &max_memory_mb,
      "estimated tree memory above which it is cropped around the latest ray origin; 0 = "
      "unbounded (MB)");
    v("keep_half_edge_voxels", &keep_half_edge_voxels,
      "half edge of the box kept around the latest ray origin by a crop, halved until the tree "
      "is below half of max_memory_mb (voxels)");
    v("discretize", &discretize,
      "reduce the rays of one insert to one per end voxel first (faster, slightly different)");
    v("dense", &dense,
      "interpolated rays inside the image triangulation of each keyframe's static points");
  }
};

// What one InsertRays call did.
struct OccupancyInsertSummary {
  int rays_inserted = 0;   // rays integrated into the tree (count)
  int rays_buffered = 0;   // rays stored while the resolution is not fixed yet (count)
  int rays_rejected = 0;   // non-finite points or points at the camera centre (count)
  int rays_truncated = 0;  // rays longer than the range bound: free space only (count)
  int interpolated_inserted = 0;  // interpolated rays integrated, one per end voxel (count)
  int interpolated_merged = 0;    // interpolated end points sharing an end voxel with another (count)
  int interpolated_rejected = 0;  // non-finite, at the camera centre or beyond the range bound (count)
};

class OccupancyMap {
 public:
  enum class Units { kUpToScale, kMetres };

  // `options` must pass Check() (a failing Check() falls back to the defaults and logs).
  OccupancyMap(const OccupancyMapOptions& options, Units units);
  ~OccupancyMap();
  OccupancyMap(const OccupancyMap&) = delete;
  OccupancyMap& operator=(const OccupancyMap&) = delete;

  // Integrates rays from the camera centre to each point (world frame, map units), and
  // to each interpolated point (weaker hit, one per end voxel, none beyond the range
  // bound), as one scan. Non-finite points and points at the camera centre are rejected
  // and counted.
  OccupancyInsertSummary InsertRays(const Eigen::Vector3d& camera_center_in_world,
                                    const std::vector<Eigen::Vector3d>& points_in_world,
                                    const std::vector<Eigen::Vector3d>& interpolated_in_world = {});

  // The world's units changed: every position is multiplied by `factor` (> 0) and the
  // map is now in `units`. Rebuilds the tree from the stored rays. Staying up to scale
  // scales the voxel edge and range bound with the geometry (the same tree, scaled);
  // switching to metres takes them from the options. Rejects a non-positive or
  // non-finite factor and leaves the map unchanged.
  Status Rescale(double factor, Units units);

  // The tree as octomap::OcTree::writeBinary(std::ostream&) writes it (a header, then
  // the maximum-likelihood tree, pruned), byte for byte: read it back with
  // OcTree::readBinary. The map itself keeps its probabilities (writeBinary would
  // convert it in place; this computes the same bytes from the const tree).
  Status Serialize(std::string* binary) const;
  // Writes the same bytes to a .bt file atomically (temporary file + rename): readable
  // with octomap::OcTree(path) and octovis.
  Status SaveBt(const std::string& path) const;

  // Occupied voxels at the finest resolution (a pruned leaf counts as all the voxels it
  // covers) (count). Kept up to date by the updates: O(1).
  int64_t NumOccupied() const;
  // True when the voxel holding the point is known and occupied.
  bool IsOccupied(const Eigen::Vector3d& point_in_world) const;
  // Occupancy probability of the voxel holding the point; nullopt if unknown (never
  // observed) or outside the tree's range.
  std::optional<double> Occupancy(const Eigen::Vector3d& point_in_world) const;
  // Centres of the occupied voxels at the finest resolution (for viewers and tests):
  // iterates over the whole tree.
  std::vector<Eigen::Vector3d> OccupiedVoxelCenters() const;

  // Voxel edge in map units; 0 while the resolution is not fixed yet.
  double resolution() const;
  // Range bound of a ray in map units; <= 0 means unbounded; 0 while the resolution is
  // not fixed yet.
  double max_range() const { return max_range_; }
  bool IsResolutionFixed() const { return tree_ != nullptr; }
  Units units() const { return units_; }
  const OccupancyMapOptions& options() const { return options_; }

  // Estimated memory of the tree: its nodes, their child arrays and the allocator's
  // overhead (bytes); O(1).
  int64_t MemoryBytes() const;
  // Crops done to bound the memory, and the occupied voxels they dropped (count).
  int64_t crops() const { return crops_; }
  int64_t occupied_voxels_dropped() const { return occupied_dropped_; }

  int64_t num_stored_rays() const { return stored_rays_; }
  int64_t rays_forgotten() const { return rays_forgotten_; }
  // Number of InsertRays calls and Rescale rebuilds that changed the tree (count); a
  // cheap way for a publisher to see whether anything changed since the last message.
  int64_t revision() const { return revision_; }

  // The underlying tree (nullptr while the resolution is not fixed yet).
  const octomap::OcTree* tree() const { return tree_.get(); }

 private:
  // The rays of one InsertRays call, kept for rebuilding.
  struct RayBatch {
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();  // camera centre (map units)
    std::vector<Eigen::Vector3f> ends;                 // end points (map units)
    std::vector<Eigen::Vector3f> interpolated;         // interpolated end points (map units)
    size_t size() const { return ends.size() + interpolated.size(); }
  };

  // Sets the voxel edge and range bound (map units) and rebuilds from the stored rays.
  void Rebuild(double resolution, double max_range);
  void InsertBatch(const RayBatch& batch, OccupancyInsertSummary* summary);
  void StoreBatch(RayBatch batch);
  // Applies the memory bound around `center` (map units).
  void BoundMemory(const Eigen::Vector3d& center);
  // Up-to-scale start: median ray length of the stored rays.
  double MedianStoredRayLength() const;
  // Resolution and range for metres from the options.
  void MetricResolution(double* resolution, double* max_range) const;

  OccupancyMapOptions options_;
  Units units_;
  std::unique_ptr<octomap::OcTree> tree_;
  double max_range_ = 0.0;
  std::deque<RayBatch> batches_;
  int64_t num_occupied_ = 0;
  // Scratch buffers of InsertBatch (OctoMap's KeyRay allocates 100k keys).
  std::unique_ptr<octomap::KeyRay> key_ray_;
  std::vector<uint64_t> updates_;
  std::vector<std::pair<uint64_t, uint32_t>> ends_by_voxel_;  // interpolated: (update, index)
  float weak_hit_log_odds_ = 0.0f;  // log-odds of dense.prob_hit
  int64_t buffered_measured_rays_ = 0;  // measured rays buffered before the resolution is fixed
  int64_t stored_rays_ = 0;
  int64_t rays_forgotten_ = 0;
  int64_t revision_ = 0;
  int64_t crops_ = 0;
  int64_t occupied_dropped_ = 0;
};

const char* OccupancyUnitsName(OccupancyMap::Units units);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OCCUPANCY_OCCUPANCY_MAP_H_
