#include "tools/planner_example/path_checker.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

namespace mbslam {
namespace planner {
namespace {

std::string Format(const Eigen::Vector3d& p) {
  char buf[96];
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f, %.2f)", p.x(), p.y(), p.z());
  return buf;
}

// Distance from a point to an axis-aligned cube of edge `edge` around `center`.
double DistanceToCube(const Eigen::Vector3d& point, const Eigen::Vector3d& center, double edge) {
  return ((point - center).cwiseAbs().array() - 0.5 * edge).max(0.0).matrix().norm();
}

}  // namespace

Status ParsePath(const std::string& text, std::vector<Waypoint>* path) {
  path->clear();
  std::string cleaned;
  cleaned.reserve(text.size());
  bool comment = false;
  for (const char c : text) {
    if (c == '#') {
      comment = true;
    } else if (c == '\n' || c == ';') {
      comment = false;
      cleaned += '\n';
    } else if (!comment) {
      cleaned += (c == ',' ? ' ' : c);
    }
  }
  std::istringstream lines(cleaned);
  std::string line;
  int number = 0;
  while (std::getline(lines, line)) {
    ++number;
    std::istringstream in(line);
    std::vector<double> values;
    std::string token;
    while (in >> token) {
      char* end = nullptr;
      const double v = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(v)) {
        return Status::Error("path waypoint " + std::to_string(number) + ": '" + token +
                             "' is not a finite number");
      }
      values.push_back(v);
    }
    if (values.empty()) {
      continue;
    }
    if (values.size() != 4) {
      return Status::Error("path waypoint " + std::to_string(number) +
                           ": expected 't x y z', got " + std::to_string(values.size()) +
                           " numbers");
    }
    Waypoint w;
    w.t_s = values[0];
    w.position = Eigen::Vector3d(values[1], values[2], values[3]);
    if (!path->empty() && w.t_s < path->back().t_s) {
      return Status::Error("path waypoint " + std::to_string(number) + ": time " +
                           std::to_string(w.t_s) + " s is before the previous waypoint's");
    }
    path->push_back(w);
  }
  if (path->empty()) {
    return Status::Error("the path has no waypoint");
  }
  return Status::Ok();
}

bool VolumeAt(const MovingObstacle& obstacle, int64_t utime, OrientedBox* box, bool* extrapolated) {
  const std::vector<OrientedBox>& v = obstacle.volumes;
  if (extrapolated != nullptr) {
    *extrapolated = false;
  }
  if (v.empty()) {
    return false;
  }
  if (utime <= v.front().utime) {
    *box = v.front();
    return true;
  }
  if (utime >= v.back().utime) {
    *box = v.back();
    if (extrapolated != nullptr) {
      *extrapolated = utime > v.back().utime;
    }
    return true;
  }
  auto after = std::lower_bound(v.begin(), v.end(), utime,
                                [](const OrientedBox& b, int64_t t) { return b.utime < t; });
  const OrientedBox& b = *after;
  const OrientedBox& a = *(after - 1);
  const double f = b.utime > a.utime ? static_cast<double>(utime - a.utime) /
                                           static_cast<double>(b.utime - a.utime)
                                     : 1.0;
  box->utime = utime;
  box->center = (1.0 - f) * a.center + f * b.center;
  box->orientation = a.orientation.slerp(f, b.orientation);
  box->half_extent = (1.0 - f) * a.half_extent + f * b.half_extent;
  box->probability = std::min(a.probability, b.probability);
  return true;
}

double DistanceToBox(const OrientedBox& box, const Eigen::Vector3d& point) {
  const Eigen::Vector3d q = box.orientation.conjugate() * (point - box.center);
  return (q.cwiseAbs() - box.half_extent.cwiseAbs()).cwiseMax(0.0).norm();
}

std::string PathConflict::Describe() const {
  std::string where = " at t=" + std::to_string(t_s).substr(0, 5) + " s (segment " +
                      std::to_string(segment) + ", robot at " + Format(robot_position) + ")";
  switch (kind) {
    case Kind::kNone:
      return "free";
    case Kind::kOccupiedVoxel:
      return "blocked by occupied voxel at " + Format(obstacle) + where;
    case Kind::kUnknownVoxel:
      return "blocked by unknown voxel at " + Format(obstacle) + where;
    case Kind::kObject: {
      char p[32];
      std::snprintf(p, sizeof(p), "%.2f", probability);
      return "blocked by object " + std::to_string(object_id) + " (predicted volume centre " +
             Format(obstacle) + ", p=" + p + (extrapolated ? ", beyond its last horizon" : "") +
             ")" + where;
    }
  }
  return "free";
}

PathChecker::PathChecker(const PathCheckOptions& options) : options_(options) {}
PathChecker::~PathChecker() = default;

void PathChecker::SetOccupancy(std::shared_ptr<const octomap::OcTree> tree) {
  tree_ = std::move(tree);
}

void PathChecker::SetObstacles(std::vector<MovingObstacle> obstacles) {
  obstacles_ = std::move(obstacles);
  for (MovingObstacle& o : obstacles_) {
    std::stable_sort(o.volumes.begin(), o.volumes.end(),
                     [](const OrientedBox& a, const OrientedBox& b) { return a.utime < b.utime; });
  }
}

bool PathChecker::VoxelConflict(const Eigen::Vector3d& p, PathConflict* conflict,
                                int* lookups) const {
  const double res = tree_->getResolution();
  const double r = options_.robot_radius;
  octomap::OcTreeKey lo, hi;
  if (!tree_->coordToKeyChecked(p.x() - r, p.y() - r, p.z() - r, lo) ||
      !tree_->coordToKeyChecked(p.x() + r, p.y() + r, p.z() + r, hi)) {
    return false;  // outside the tree's coordinate range: nothing known there
  }
  double best_occupied = INFINITY, best_unknown = INFINITY;
  Eigen::Vector3d occupied_at = Eigen::Vector3d::Zero();
  Eigen::Vector3d unknown_at = Eigen::Vector3d::Zero();
  for (unsigned x = lo[0]; x <= hi[0]; ++x) {
    for (unsigned y = lo[1]; y <= hi[1]; ++y) {
      for (unsigned z = lo[2]; z <= hi[2]; ++z) {
        const octomap::OcTreeKey key(static_cast<octomap::key_type>(x),
                                     static_cast<octomap::key_type>(y),
                                     static_cast<octomap::key_type>(z));
        const octomap::point3d c = tree_->keyToCoord(key);
        const Eigen::Vector3d center(c.x(), c.y(), c.z());
        const double d = DistanceToCube(p, center, res);
        if (d > r) {
          continue;
        }
        ++*lookups;
        const octomap::OcTreeNode* node = tree_->search(key);
        if (node != nullptr && tree_->isNodeOccupied(node)) {
          if (d < best_occupied) {
            best_occupied = d;
            occupied_at = center;
          }
        } else if (node == nullptr && options_.unknown_is_occupied && d < best_unknown) {
          best_unknown = d;
          unknown_at = center;
        }
      }
    }
  }
  if (std::isfinite(best_occupied)) {
    conflict->kind = PathConflict::Kind::kOccupiedVoxel;
    conflict->obstacle = occupied_at;
    return true;
  }
  if (std::isfinite(best_unknown)) {
    conflict->kind = PathConflict::Kind::kUnknownVoxel;
    conflict->obstacle = unknown_at;
    return true;
  }
  return false;
}

Status PathChecker::Check(const std::vector<Waypoint>& path, int64_t now_utime,
                          PathConflict* conflict, PathCheckSummary* summary) const {
  *conflict = PathConflict();
  PathCheckSummary local;
  PathCheckSummary& s = summary != nullptr ? *summary : local;
  s = PathCheckSummary();
  if (!options_.Check()) {
    return Status::Error("path check options: " + LastOptionError());
  }
  if (path.empty()) {
    return Status::Error("the path has no waypoint");
  }
  for (size_t i = 0; i < path.size(); ++i) {
    if (!std::isfinite(path[i].t_s) || !path[i].position.allFinite()) {
      return Status::Error("waypoint " + std::to_string(i) + " is not finite");
    }
    if (i > 0 && path[i].t_s < path[i - 1].t_s) {
      return Status::Error("waypoint " + std::to_string(i) + " is earlier than the one before");
    }
  }
  // The path as segments, plus a rest at the last waypoint until the horizon.
  std::vector<Waypoint> p = path;
  if (options_.hold_last_waypoint && p.back().t_s < options_.horizon_s) {
    Waypoint rest = p.back();
    rest.t_s = options_.horizon_s;
    p.push_back(rest);
  }
  if (p.size() == 1) {
    p.push_back(p.back());  // a single waypoint: one position at one time
  }
  double step = options_.max_step;
  if (step <= 0.0) {
    double scale = options_.robot_radius > 0.0 ? options_.robot_radius : 0.1;
    if (tree_) {
      scale = std::min(scale, tree_->getResolution());
    }
    step = 0.5 * scale;
  }
  const double horizon = options_.horizon_s;
  bool any_checked = false;
  Eigen::Vector3d last_static_check = Eigen::Vector3d::Constant(NAN);
  for (size_t i = 0; i + 1 < p.size(); ++i) {
    const Waypoint& a = p[i];
    const Waypoint& b = p[i + 1];
    const double t0 = std::max(a.t_s, 0.0);
    const double t1 = std::min(b.t_s, horizon);
    if (t1 < t0 || (t1 == t0 && b.t_s > a.t_s)) {
      continue;  // outside [0, horizon]
    }
    const double duration = b.t_s - a.t_s;
    // Fraction of the segment at time t (a segment without duration is a jump at a.t_s).
    auto fraction = [&](double t) { return duration > 0.0 ? (t - a.t_s) / duration : 0.0; };
    const double f0 = fraction(t0);
    const double f1 = duration > 0.0 ? fraction(t1) : 1.0;
    const double length = (f1 - f0) * (b.position - a.position).norm();
    const int n = std::max({1, static_cast<int>(std::ceil(length / step)),
                            static_cast<int>(std::ceil((t1 - t0) / options_.max_time_step_s))});
    for (int k = 0; k <= n; ++k) {
      if (k == 0 && any_checked) {
        continue;  // the previous segment's last position
      }
      any_checked = true;
      const double f = f0 + (f1 - f0) * k / n;
      const double t = duration > 0.0 ? a.t_s + f * duration : a.t_s;
      const Eigen::Vector3d position = a.position + f * (b.position - a.position);
      ++s.positions_checked;
      s.checked_until_s = t;
      PathConflict c;
      c.t_s = t;
      c.segment = static_cast<int>(std::min(i, path.size() - 1));
      c.robot_position = position;
      // The static world does not change: a position already checked (waiting) is not
      // looked up again.
      if (tree_ && position != last_static_check) {
        last_static_check = position;
        if (VoxelConflict(position, &c, &s.voxels_tested)) {
          *conflict = c;
          return Status::Ok();
        }
      }
      const int64_t utime = now_utime + static_cast<int64_t>(std::llround(t * 1e6));
      for (const MovingObstacle& o : obstacles_) {
        OrientedBox box;
        bool extrapolated = false;
        if (!VolumeAt(o, utime, &box, &extrapolated) ||
            box.probability < options_.min_volume_probability) {
          continue;
        }
        if (DistanceToBox(box, position) <= options_.robot_radius) {
          c.kind = PathConflict::Kind::kObject;
          c.object_id = o.id;
          c.obstacle = box.center;
          c.extrapolated = extrapolated;
          c.probability = box.probability;
          *conflict = c;
          return Status::Ok();
        }
      }
    }
  }
  return Status::Ok();
}

}  // namespace planner
}  // namespace mbslam
