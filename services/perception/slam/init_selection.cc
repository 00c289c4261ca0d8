#include "services/perception/slam/init_selection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <opencv2/calib3d.hpp>

#include <Eigen/Eigenvalues>

#include "services/perception/geometry/polygon.h"
#include "services/perception/geometry/rigid3.h"

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

namespace {

// Sampson distance of x0 <-> x1 under E (normalised coordinates).
double SampsonDistance(const Eigen::Matrix3d& E, const Eigen::Vector2d& x0, const Eigen::Vector2d& x1) {
  const Eigen::Vector3d a = x0.homogeneous();
  const Eigen::Vector3d b = x1.homogeneous();
  const Eigen::Vector3d Ea = E * a;
  const Eigen::Vector3d Etb = E.transpose() * b;
  const double num = b.dot(Ea);
  const double den = Ea.head<2>().squaredNorm() + Etb.head<2>().squaredNorm();
  return den > 0.0 ? std::abs(num) / std::sqrt(den) : std::numeric_limits<double>::infinity();
}

}  // namespace

std::optional<KnownRotationTranslation> TranslationGivenRotation(const std::vector<Eigen::Vector2d>& x0,
                                                                 const std::vector<Eigen::Vector2d>& x1,
                                                                 const Eigen::Matrix3d& R, double threshold,
                                                                 int iterations) {
  const size_t n = std::min(x0.size(), x1.size());
  if (n < 2) return std::nullopt;
  std::vector<Eigen::Vector3d> normals(n);
  for (size_t i = 0; i < n; ++i) normals[i] = (R * x0[i].homogeneous()).cross(x1[i].homogeneous());
  auto score = [&](const Eigen::Vector3d& t, std::vector<uint8_t>* mask) {
    const Eigen::Matrix3d E = Hat(t) * R;
    int c = 0;
    mask->assign(n, 0);
    for (size_t i = 0; i < n; ++i) {
      if (SampsonDistance(E, x0[i], x1[i]) <= threshold) {
        (*mask)[i] = 1;
        ++c;
      }
    }
    return c;
  };
  std::mt19937 rng(12345);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  KnownRotationTranslation best;
  std::vector<uint8_t> mask;
  for (int it = 0; it < iterations; ++it) {
    const size_t i = pick(rng);
    const size_t j = pick(rng);
    if (i == j) continue;
    const Eigen::Vector3d t = normals[i].cross(normals[j]);
    if (t.norm() < 1e-12) continue;
    const int c = score(t.normalized(), &mask);
    if (c > best.count) {
      best.count = c;
      best.t_unit = t.normalized();
      best.inliers = mask;
    }
  }
  if (best.count < 2) return std::nullopt;
  // Least squares on the inliers, |t| = 1: the epipolar residual n_i . t over its Sampson
  // gradient norm at the current t (iteratively reweighted).
  for (int round = 0; round < 4; ++round) {
    const Eigen::Matrix3d E = Hat(best.t_unit) * R;
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < n; ++i) {
      if (!best.inliers[i]) continue;
      const Eigen::Vector3d Ea = E * x0[i].homogeneous();
      const Eigen::Vector3d Etb = E.transpose() * x1[i].homogeneous();
      const double den = Ea.head<2>().squaredNorm() + Etb.head<2>().squaredNorm();
      if (den > 1e-12) A += normals[i] * normals[i].transpose() / den;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
    if (eig.info() != Eigen::Success) break;
    Eigen::Vector3d t = eig.eigenvectors().col(0).normalized();
    if (t.dot(best.t_unit) < 0.0) t = -t;
    const int c = score(t, &mask);
    if (c < best.count) break;
    best.count = c;
    best.t_unit = t;
    best.inliers = mask;
  }
  return best;
}

}  // namespace mbslam
