#include "tools/eval/point_metrics.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/util/atomic_file.h"

namespace mbslam {
namespace eval {

size_t NearestPoint::KeyHash::operator()(const Key& k) const {
  uint64_t h = static_cast<uint64_t>(k.x) * 73856093ULL;
  h ^= static_cast<uint64_t>(k.y) * 19349663ULL;
  h ^= static_cast<uint64_t>(k.z) * 83492791ULL;
  return static_cast<size_t>(h);
}

NearestPoint::Key NearestPoint::KeyOf(const Eigen::Vector3d& p) const {
  return {static_cast<int64_t>(std::floor(p.x() / cell_)),
          static_cast<int64_t>(std::floor(p.y() / cell_)),
          static_cast<int64_t>(std::floor(p.z() / cell_))};
}

NearestPoint::NearestPoint(const std::vector<Eigen::Vector3d>& points, double cell_m)
    : cell_(std::max(cell_m, 1e-6)), points_(points) {
  for (size_t i = 0; i < points_.size(); ++i) {
    cells_[KeyOf(points_[i])].push_back(static_cast<int>(i));
  }
}

double NearestPoint::Distance(const Eigen::Vector3d& query, double max_distance) const {
  double best = max_distance;
  const Key c = KeyOf(query);
  const int64_t reach = static_cast<int64_t>(std::ceil(max_distance / cell_));
  // Grow the searched cube of cells until it cannot hold anything closer than `best`.
  for (int64_t r = 0; r <= reach; ++r) {
    if (static_cast<double>(r - 1) * cell_ > best) {
      break;
    }
    for (int64_t dx = -r; dx <= r; ++dx) {
      for (int64_t dy = -r; dy <= r; ++dy) {
        for (int64_t dz = -r; dz <= r; ++dz) {
          if (std::max({std::llabs(dx), std::llabs(dy), std::llabs(dz)}) != r) {
            continue;  // the shell only
          }
          auto it = cells_.find({c.x + dx, c.y + dy, c.z + dz});
          if (it == cells_.end()) {
            continue;
          }
          for (int i : it->second) {
            best = std::min(best, (points_[static_cast<size_t>(i)] - query).norm());
          }
        }
      }
    }
  }
  return best;
}

ReconstructionError CompareToSurface(const std::vector<Eigen::Vector3d>& reconstructed,
                                     const std::vector<Eigen::Vector3d>& truth, double threshold,
                                     double max_distance) {
  ReconstructionError r;
  const double cell = std::max(threshold, 1e-3);
  const NearestPoint to_truth(truth, cell);
  std::vector<double> d;
  for (const auto& p : reconstructed) {
    const double dist = to_truth.Distance(p, max_distance);
    if (dist >= max_distance) {
      ++r.outliers;
    }
    d.push_back(dist);
  }
  r.accuracy = ErrorStats::From(d);
  if (!truth.empty()) {
    const NearestPoint to_recon(reconstructed, cell);
    int covered = 0;
    for (const auto& g : truth) {
      covered += to_recon.Distance(g, threshold) < threshold ? 1 : 0;
    }
    r.completeness = static_cast<double>(covered) / static_cast<double>(truth.size());
  }
  return r;
}

Status ReadPointsFile(const std::string& path, std::vector<Eigen::Vector3d>* points) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text));
  points->clear();
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line[0] == '#') {
      continue;
    }
    std::istringstream ls(line);
    Eigen::Vector3d p;
    if (!(ls >> p.x() >> p.y() >> p.z())) {
      return Status::Error(path + ":" + std::to_string(line_no) + ": want 'x y z'");
    }
    points->push_back(p);
  }
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
