#ifndef MBSLAM_TOOLS_OCCUPANCY_EVAL_OCCUPANCY_EVAL_H_
#define MBSLAM_TOOLS_OCCUPANCY_EVAL_OCCUPANCY_EVAL_H_

// Occupancy map against the voxelised ground truth of a simulator sequence (issue 7,
// item 4). The truth is the static world's surface as the camera saw it: every depth
// pixel whose mask is 0 (the static body), back-projected with the true camera pose and
// put in a voxel grid of edge `resolution`. The estimated map lives in the SLAM frame
// (map units), so its occupied voxels are first mapped into the ground-truth frame by
// the Sim(3) (or SE(3)) Umeyama alignment of the estimated camera trajectory to the true
// one (tools/eval).
//
//   precision = occupied estimated voxels with a true surface voxel within one voxel
//               (26-neighbourhood) / occupied estimated voxels
//   recall    = observed true surface voxels with an occupied estimated voxel within
//               one voxel / observed true surface voxels
//
// "Observed" true voxels are those seen from no farther than `max_range_m` (the range
// bound the map was built with): space beyond it can never be in the map. Precision
// counts against every true surface voxel, at any range.

#include <cstdint>
#include <string>
#include <unordered_set>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"
#include "tools/eval/datasets.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

struct OccupancyEvalOptions {
  double resolution_m = 0.0;         // voxel edge of the scoring grid (m); 0 = the map's own voxel
                                     // edge in metres after alignment
  double max_range_m = 20.0;         // true voxels count for recall when seen within this range (m)
  int pixel_step = 1;                // depth pixels used every this many rows and columns (px)
  int frame_step = 1;                // frames used every this many (count)
  bool all_frames = false;           // use frames outside the estimated trajectory's time span too
  std::string alignment = "sim3";    // sim3 | se3 | none: estimated frame -> ground truth
  int64_t max_time_diff_us = 20000;  // association of estimated and true poses (µs)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("resolution_m", &resolution_m,
      "voxel edge of the scoring grid; 0 = the map's voxel edge in metres after alignment (m)");
    v("max_range_m", &max_range_m, "true voxels count for recall when seen within this range (m)");
    v("pixel_step", &pixel_step, "depth pixels used every this many rows and columns (px)");
    v("frame_step", &frame_step, "frames used every this many (count)");
    v("all_frames", &all_frames,
      "use frames outside the estimated trajectory's time span too (bool)");
    v("alignment", &alignment, "sim3 | se3 | none: estimated frame -> ground truth");
    v("max_time_diff_us", &max_time_diff_us, "association of estimated and true poses (µs)");
  }
};

// A set of voxels of a uniform grid: key = floor(p / resolution) per axis, packed.
class VoxelGrid {
 public:
  explicit VoxelGrid(double resolution) : resolution_(resolution) {}
  // False if the point is not finite or farther than ~1e6 voxels from the origin.
  bool Insert(const Eigen::Vector3d& point);
  bool Contains(const Eigen::Vector3d& point) const;
  // True if the voxel of the point or one of its 26 neighbours is in the set.
  bool ContainsNear(const Eigen::Vector3d& point) const;
  size_t size() const { return keys_.size(); }
  double resolution() const { return resolution_; }
  // Centres of all voxels (any order).
  std::vector<Eigen::Vector3d> Centers() const;

 private:
  static constexpr int64_t kOffset = int64_t{1} << 20;  // keys are 21-bit signed per axis
  bool KeyOf(const Eigen::Vector3d& point, int64_t ijk[3]) const;
  static uint64_t Pack(const int64_t ijk[3]);
  double resolution_;
  std::unordered_set<uint64_t> keys_;
};

// Occupied voxels of an OctoMap .bt file (finest voxels; pruned leaves expanded).
struct OccupiedVoxels {
  double resolution = 0.0;               // voxel edge (map units)
  std::vector<Eigen::Vector3d> centers;  // map frame (map units)
};
Status ReadOccupiedVoxels(const std::string& bt_path, OccupiedVoxels* voxels);
// The same from OcTree::writeBinary bytes (e.g. occupancy_t.data).
Status ParseOccupiedVoxels(const std::string& binary, OccupiedVoxels* voxels);

// The static surface seen in a sequence's depth maps.
struct TrueSurface {
  VoxelGrid all{0.1};       // every static depth pixel, any range
  VoxelGrid observed{0.1};  // those seen within max_range_m
  int frames_used = 0;
  int64_t pixels_used = 0;
};
// Voxelises the depth maps (depth/*.exr in m or *.png in mm, z along the optical axis)
// of the frames with utime in [first_utime, last_utime], static pixels only (masks/
// = 0, or every pixel when there are no masks), posed by cam_trajectory.tum.
Status VoxelizeTrueSurface(const SequenceFolder& sequence, double resolution_m,
                           const OccupancyEvalOptions& options, int64_t first_utime,
                           int64_t last_utime, TrueSurface* surface);

struct OccupancyScore {
  double precision = 0.0;         // fraction
  double recall = 0.0;            // fraction
  int64_t voxels_est = 0;         // occupied estimated voxels in the scoring grid (count)
  int64_t voxels_est_near = 0;    // ... with a true surface voxel within one voxel (count)
  int64_t voxels_true = 0;        // observed true surface voxels (count)
  int64_t voxels_true_found = 0;  // ... with an estimated voxel within one voxel (count)
  int64_t voxels_true_all = 0;    // true surface voxels at any range (count)
};
// `est` are the estimated voxels in the ground-truth frame (metres), each a cube of edge
// `est_voxel_m` rotated by `est_rotation`; cubes larger than the scoring voxel are
// sampled at the scoring resolution.
OccupancyScore ScoreOccupancy(const std::vector<Eigen::Vector3d>& est_centers_in_gt,
                              double est_voxel_m, const Eigen::Quaterniond& est_rotation,
                              const TrueSurface& truth);

struct OccupancyEvalResult {
  OccupancyScore score;
  double resolution_m = 0.0;      // scoring voxel edge (m)
  double est_resolution = 0.0;    // the map's voxel edge (map units)
  double est_resolution_m = 0.0;  // ... in metres after alignment (m)
  Sim3d gt_from_est;              // the alignment applied to the map
  int aligned_poses = 0;          // trajectory poses used for the alignment (count)
  double ate_rmse_m = 0.0;        // camera position error after alignment (m)
  int frames_used = 0;            // depth maps voxelised (count)
};

// The whole evaluation: `est_trajectory` (world_from_cam in the map's frame, TUM) may be
// empty with alignment "none".
Status EvaluateOccupancy(const std::string& bt_path, const Trajectory& est_trajectory,
                         const std::string& sequence_dir, const OccupancyEvalOptions& options,
                         OccupancyEvalResult* result);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_OCCUPANCY_EVAL_OCCUPANCY_EVAL_H_
