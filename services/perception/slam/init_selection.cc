#include "services/perception/slam/init_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>

#include "services/perception/geometry/polygon.h"

namespace mbslam {

std::vector<InitMotionGroup> FindMotionGroups(const std::vector<Eigen::Vector2d>& xr,
                                              const std::vector<Eigen::Vector2d>& xn, double threshold,
                                              int min_count, int max_groups) {
  std::vector<InitMotionGroup> groups;
  const size_t n = std::min(xr.size(), xn.size());
  std::vector<size_t> remaining(n);
  for (size_t i = 0; i < n; ++i) remaining[i] = i;
  const cv::Mat K = cv::Mat::eye(3, 3, CV_64F);
  while (static_cast<int>(groups.size()) < max_groups && static_cast<int>(remaining.size()) >= std::max(min_count, 5)) {
    std::vector<cv::Point2d> pr, pn;
    pr.reserve(remaining.size());
    pn.reserve(remaining.size());
    for (size_t i : remaining) {
      pr.emplace_back(xr[i].x(), xr[i].y());
      pn.emplace_back(xn[i].x(), xn[i].y());
    }
    cv::Mat mask;
    const cv::Mat E = cv::findEssentialMat(pr, pn, K, cv::RANSAC, 0.999, threshold, 2000, mask);
    if (E.empty() || mask.empty()) break;
    InitMotionGroup g;
    g.inliers.assign(n, 0);
    std::vector<size_t> rest;
    for (size_t k = 0; k < remaining.size(); ++k) {
      if (mask.at<uint8_t>(static_cast<int>(k))) {
        g.inliers[remaining[k]] = 1;
        ++g.count;
      } else {
        rest.push_back(remaining[k]);
      }
    }
    if (g.count < min_count) break;
    groups.push_back(std::move(g));
    remaining = std::move(rest);
  }
  return groups;
}

void ScoreMotionGroups(const std::vector<Eigen::Vector2d>& xn, const std::vector<Eigen::Vector2d>& all_xy,
                       const std::vector<std::vector<Eigen::Vector2f>>& moving_hulls_xy, int cols, int rows,
                       std::vector<InitMotionGroup>* groups, bool require_majority) {
  cols = std::max(cols, 1);
  rows = std::max(rows, 1);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = Eigen::Vector2d::Constant(std::numeric_limits<double>::lowest());
  for (const Eigen::Vector2d& p : all_xy) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  for (const Eigen::Vector2d& p : xn) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const Eigen::Vector2d size = (hi - lo).cwiseMax(Eigen::Vector2d::Constant(1e-9));
  auto cell_of = [&](const Eigen::Vector2d& p) {
    const int cx = std::clamp(static_cast<int>((p.x() - lo.x()) / size.x() * cols), 0, cols - 1);
    const int cy = std::clamp(static_cast<int>((p.y() - lo.y()) / size.y() * rows), 0, rows - 1);
    return cy * cols + cx;
  };
  const size_t num_cells = static_cast<size_t>(cols) * static_cast<size_t>(rows);
  std::vector<int> features(num_cells, 0), correspondences(num_cells, 0);
  for (const Eigen::Vector2d& p : all_xy) ++features[static_cast<size_t>(cell_of(p))];
  std::vector<int> cell(xn.size());
  std::vector<uint8_t> in_hull(xn.size(), 0);
  for (size_t i = 0; i < xn.size(); ++i) {
    cell[i] = cell_of(xn[i]);
    ++correspondences[static_cast<size_t>(cell[i])];
    const Eigen::Vector2f q = xn[i].cast<float>();
    for (const auto& hull : moving_hulls_xy) {
      if (hull.size() >= 3 && InsideConvexHull(hull, q)) {
        in_hull[i] = 1;
        break;
      }
    }
  }
  int occupied = 0;
  for (size_t c = 0; c < num_cells; ++c) occupied += (features[c] > 0 || correspondences[c] > 0) ? 1 : 0;
  for (InitMotionGroup& g : *groups) {
    std::vector<int> members(num_cells, 0);
    int inside = 0;
    for (size_t i = 0; i < xn.size() && i < g.inliers.size(); ++i) {
      if (!g.inliers[i]) continue;
      ++members[static_cast<size_t>(cell[i])];
      inside += in_hull[i];
    }
    int covered = 0;
    for (size_t c = 0; c < num_cells; ++c) {
      if (members[c] >= 2 && (!require_majority || 2 * members[c] >= correspondences[c])) ++covered;
    }
    g.coverage = occupied > 0 ? static_cast<double>(covered) / occupied : 0.0;
    g.hull_share = g.count > 0 ? static_cast<double>(inside) / g.count : 0.0;
  }
}

int SelectStaticGroup(const std::vector<InitMotionGroup>& groups, double min_coverage, double max_hull_share) {
  int best = -1;
  for (size_t i = 0; i < groups.size(); ++i) {
    const InitMotionGroup& g = groups[i];
    if (g.coverage < min_coverage || g.hull_share > max_hull_share) continue;
    if (best < 0 || g.coverage > groups[static_cast<size_t>(best)].coverage ||
        (g.coverage == groups[static_cast<size_t>(best)].coverage && g.count > groups[static_cast<size_t>(best)].count)) {
      best = static_cast<int>(i);
    }
  }
  return best;
}

}  // namespace mbslam
