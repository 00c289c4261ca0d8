#ifndef MBSLAM_TOOLS_PLANNER_EXAMPLE_PATH_CHECKER_H_
#define MBSLAM_TOOLS_PLANNER_EXAMPLE_PATH_CHECKER_H_

// Is a timed path free over the next second? The planner-side use of mbslam's outputs
// (tools/planner_example/README.md): a sphere of the robot's radius swept along the
// path is tested against the occupied voxels of the static world's OctoMap and against
// every moving object's predicted volume at the matching time (oriented boxes,
// interpolated between the published horizons). No LCM here: planner_example_main.cc
// decodes the messages into these structs.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/config/options.h"
#include "common/util/status.h"

namespace octomap {
class OcTree;
}  // namespace octomap

namespace mbslam {
namespace planner {

// A point of the path: where the robot (its centre) is to be, and when.
struct Waypoint {
  double t_s = 0.0;                                    // time after "now" (s)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame (m, or map units)
};

// Path text: one waypoint per line "t x y z" (whitespace or commas, '#' comments), or
// on one line separated by ';' ("0,0,0,0; 0.5,1,0,0"). Times must not decrease.
Status ParsePath(const std::string& text, std::vector<Waypoint>* path);

// Space a moving object takes at one time (predicted_volume_t).
struct OrientedBox {
  int64_t utime = 0;                                                // µs
  Eigen::Vector3d center = Eigen::Vector3d::Zero();                 // world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world_from_box
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();            // along the box axes
  double probability = 1.0;  // particle mass inside the box [0, 1]
};

// One moving object with its current (horizon 0) and predicted volumes.
struct MovingObstacle {
  int id = 0;
  std::vector<OrientedBox> volumes;  // by increasing utime
};

// The object's volume at `utime`: linear in centre and half extents, slerp in
// orientation, between the two volumes around it; the first volume before it, the last
// after it (`extrapolated` then says so). False if the object has no volume.
bool VolumeAt(const MovingObstacle& obstacle, int64_t utime, OrientedBox* box,
              bool* extrapolated = nullptr);

// Distance from a point to a (solid) oriented box; 0 inside.
double DistanceToBox(const OrientedBox& box, const Eigen::Vector3d& point);

struct PathCheckOptions {
  double robot_radius = 0.3;      // radius of the sphere around the robot's centre (m or map units)
  double horizon_s = 1.0;         // only the part of the path in [0, horizon] is checked (s)
  double max_step = 0.0;          // largest distance between checked positions (m or map units);
                                  // 0 = half of min(voxel edge, robot radius)
  double max_time_step_s = 0.02;  // largest time between checked positions (s)
  bool unknown_is_occupied = false;     // never-observed voxels block too (a monocular map is
                                        // sparse: mostly unknown; off by default)
  double min_volume_probability = 0.0;  // predicted volumes below this probability are
                                        // ignored [0, 1]
  bool hold_last_waypoint = true;       // the robot stays at the last waypoint until the horizon

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(robot_radius, 0.0);
    MBSLAM_CHECK_OPTION_GT(horizon_s, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_step, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_time_step_s, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_volume_probability, 0.0);
    MBSLAM_CHECK_OPTION_LE(min_volume_probability, 1.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("robot_radius", &robot_radius,
      "radius of the sphere around the robot's centre (m or map units)");
    v("horizon_s", &horizon_s, "only the part of the path in [0, horizon] is checked (s)");
    v("max_step", &max_step,
      "largest distance between checked positions; 0 = half of min(voxel edge, robot radius) "
      "(m or map units)");
    v("max_time_step_s", &max_time_step_s, "largest time between checked positions (s)");
    v("unknown_is_occupied", &unknown_is_occupied, "never-observed voxels block too");
    v("min_volume_probability", &min_volume_probability,
      "predicted volumes below this probability are ignored [0, 1]");
    v("hold_last_waypoint", &hold_last_waypoint,
      "the robot stays at the last waypoint until the horizon");
  }
};

// The first conflict along the path, in time.
struct PathConflict {
  enum class Kind { kNone, kOccupiedVoxel, kUnknownVoxel, kObject };
  Kind kind = Kind::kNone;
  double t_s = 0.0;                                          // time after "now" (s)
  int segment = -1;                                          // path[segment] -> path[segment + 1]
  Eigen::Vector3d robot_position = Eigen::Vector3d::Zero();  // world frame
  Eigen::Vector3d obstacle = Eigen::Vector3d::Zero();        // voxel centre or box centre (world)
  int object_id = 0;                                         // kObject
  bool extrapolated = false;  // kObject: beyond the last published horizon
  double probability = 0.0;   // kObject: the volume's probability

  bool blocked() const { return kind != Kind::kNone; }
  // "free", or "blocked by occupied voxel at (x, y, z) ..." with the details.
  std::string Describe() const;
};

// What the check looked at.
struct PathCheckSummary {
  int positions_checked = 0;   // sampled robot positions (count)
  int voxels_tested = 0;       // voxel look-ups (count)
  double checked_until_s = 0;  // last time checked (s after now)
};

class PathChecker {
 public:
  explicit PathChecker(const PathCheckOptions& options);
  ~PathChecker();

  // The static world (nullptr: none received; every path is then only checked against
  // the objects).
  void SetOccupancy(std::shared_ptr<const octomap::OcTree> tree);
  void SetObstacles(std::vector<MovingObstacle> obstacles);

  // Checks `path` (times relative to `now_utime`, the time of the estimate the
  // obstacles are from) over [0, horizon_s].
  Status Check(const std::vector<Waypoint>& path, int64_t now_utime, PathConflict* conflict,
               PathCheckSummary* summary = nullptr) const;

  const PathCheckOptions& options() const { return options_; }

 private:
  // The first blocking voxel near `p` (sphere of the robot radius), if any.
  bool VoxelConflict(const Eigen::Vector3d& p, PathConflict* conflict, int* lookups) const;

  PathCheckOptions options_;
  std::shared_ptr<const octomap::OcTree> tree_;
  std::vector<MovingObstacle> obstacles_;
};

}  // namespace planner
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_PLANNER_EXAMPLE_PATH_CHECKER_H_
