#ifndef MBSLAM_TOOLS_EVAL_POINT_METRICS_H_
#define MBSLAM_TOOLS_EVAL_POINT_METRICS_H_

// Reconstruction accuracy against ground-truth surface points (e.g. the simulator's
// points/<id>.txt): accuracy = distance of each reconstructed point to the nearest true
// surface sample, completeness = fraction of true samples with a reconstructed point
// nearby. Both clouds must be in the same frame and units (align first).

#include <Eigen/Core>

#include <string>
#include <unordered_map>
#include <vector>

#include "common/util/status.h"
#include "tools/eval/camera_metrics.h"

namespace mbslam {
namespace eval {

// Nearest-neighbour queries on a fixed point set (uniform voxel hashing).
class NearestPoint {
 public:
  // cell_m: voxel size, about the expected query distance (m).
  NearestPoint(const std::vector<Eigen::Vector3d>& points, double cell_m);
  // Distance to the nearest point, searching at most `max_distance` far; returns
  // max_distance when nothing is that close (or the set is empty).
  double Distance(const Eigen::Vector3d& query, double max_distance) const;

 private:
  struct Key {
    int64_t x, y, z;
    bool operator==(const Key& o) const { return x == o.x && y == o.y && z == o.z; }
  };
  struct KeyHash {
    size_t operator()(const Key& k) const;
  };
  Key KeyOf(const Eigen::Vector3d& p) const;
  double cell_;
  std::vector<Eigen::Vector3d> points_;
  std::unordered_map<Key, std::vector<int>, KeyHash> cells_;
};

struct ReconstructionError {
  ErrorStats accuracy;  // reconstructed point -> nearest true sample (m), capped at max_distance
  double completeness =
      0.0;           // fraction of true samples within `threshold` of a reconstructed point
  int outliers = 0;  // reconstructed points farther than max_distance from the truth (count)
};

ReconstructionError CompareToSurface(const std::vector<Eigen::Vector3d>& reconstructed,
                                     const std::vector<Eigen::Vector3d>& truth, double threshold,
                                     double max_distance);

// "x y z" per line ('#' comments): the simulator's points/<id>.txt.
Status ReadPointsFile(const std::string& path, std::vector<Eigen::Vector3d>* points);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_POINT_METRICS_H_
