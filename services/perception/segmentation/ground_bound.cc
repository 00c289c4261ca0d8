#include "services/perception/segmentation/ground_bound.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Dense>

namespace mbslam {

bool PairInverseDepth(const Eigen::Vector2d& x_r, const Eigen::Vector2d& x_n, const Eigen::Matrix3d& R,
                      const Eigen::Vector3d& t, double sigma, double* s, double* s_sigma) {
  const Eigen::Vector3d a = R * x_r.homogeneous();
  if (a.z() <= 1e-9) return false;
  // x_n (a_z + t_z s) = a_x + t_x s and the same in y: c s = b, least squares.
  const Eigen::Vector2d c(x_n.x() * t.z() - t.x(), x_n.y() * t.z() - t.y());
  const Eigen::Vector2d b(a.x() - x_n.x() * a.z(), a.y() - x_n.y() * a.z());
  const double cc = c.squaredNorm();
  if (cc < 1e-18) return false;
  *s = c.dot(b) / cc;
  // Each equation's residual is (a_z + t_z s) times the position error.
  const double w = a.z() + t.z() * *s;
  if (w <= 1e-9) return false;  // the point would be behind the current camera
  *s_sigma = w * sigma / std::sqrt(cc);
  return true;
}

namespace {

struct InverseDepthSample {
  Eigen::Vector3d ray;  // [x y 1] in the reference camera
  double s = 0.0;
  double sigma = 0.0;
  double tolerance = 0.0;  // of an inlier's residual: inlier_sigmas * sigma + inlier_rel * |s|
  double parallax_px = 0.0;
};

double TiltDeg(const Eigen::Vector3d& m) {
  const double n = m.norm();
  if (n < 1e-15) return 180.0;
  return std::acos(std::clamp(m.y() / n, -1.0, 1.0)) * 180.0 / M_PI;
}

bool IsInlier(const InverseDepthSample& p, const Eigen::Vector3d& m) {
  return std::abs(p.ray.dot(m) - p.s) <= p.tolerance;
}

struct PlaneScore {
  int inliers = 0;
  double cost = 0.0;       // MSAC: sum over tracks of min((residual / tolerance)^2, 1)
  bool qualified = false;  // the inliers' depths span the required ratio, few tracks beyond
};

// `imprecise` (tracks not fitted, counted only if beyond the plane) may be null: a raw
// score whose `qualified` is not meaningful.
PlaneScore Score(const std::vector<InverseDepthSample>& pts, const std::vector<InverseDepthSample>* imprecise,
                 const Eigen::Vector3d& m, const PairGroundOptions& o) {
  PlaneScore score;
  int beyond = 0;
  if (imprecise) {
    for (const InverseDepthSample& p : *imprecise) {
      const double s_plane = p.ray.dot(m);
      beyond += s_plane > 0.0 && p.s + p.tolerance < s_plane;
    }
  }
  double s_min = std::numeric_limits<double>::infinity(), s_max = 0.0;
  for (const InverseDepthSample& p : pts) {
    const double r = p.s - p.ray.dot(m);
    if (std::abs(r) > p.tolerance) {
      beyond += r < 0.0;
      score.cost += 1.0;
      continue;
    }
    score.cost += (r / p.tolerance) * (r / p.tolerance);
    ++score.inliers;
    s_min = std::min(s_min, p.s);
    s_max = std::max(s_max, p.s);
  }
  score.qualified = score.inliers > 0 && s_max >= o.min_depth_ratio * s_min &&
                    beyond <= o.max_beyond_share * score.inliers;
  return score;
}

// Weighted least squares of m over the inliers of *m, each weighted by the inverse
// square of sigma + inlier_rel * s (so that no few precise points pull the plane away
// from the rest); false if too few.
bool Refit(const std::vector<InverseDepthSample>& pts, const PairGroundOptions& o, Eigen::Vector3d* m) {
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  int n = 0;
  for (const InverseDepthSample& p : pts) {
    if (!IsInlier(p, *m)) continue;
    const double tolerance = p.sigma + o.inlier_rel * std::abs(p.s);
    const double w = 1.0 / (tolerance * tolerance);
    A.selfadjointView<Eigen::Upper>().rankUpdate(p.ray, w);
    b += w * p.s * p.ray;
    ++n;
  }
  if (n < 3) return false;
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(A.selfadjointView<Eigen::Upper>());
  if (ldlt.info() != Eigen::Success) return false;
  const Eigen::Vector3d next = ldlt.solve(b);
  if (!next.allFinite()) return false;
  *m = next;
  return true;
}

}  // namespace

std::optional<PairGroundPlane> FitPairGroundPlane(const std::vector<Eigen::Vector2d>& x_r,
                                                  const std::vector<Eigen::Vector2d>& x_n,
                                                  const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                                  double focal_px, double sigma_px,
                                                  const PairGroundOptions& o) {
  if (x_r.size() != x_n.size() || focal_px <= 0.0 || !t.allFinite() || !R.allFinite() || t.norm() < 1e-12) return std::nullopt;
  const double sigma = sigma_px / focal_px;
  // The plane is fitted to the tracks with a precise inverse depth (a plane below the
  // camera holds positive ones); every track, however imprecise, can tell that it lies
  // beyond a plane (far tracks mostly are imprecise, and a wrong plane has them beyond).
  std::vector<InverseDepthSample> pts, imprecise;
  pts.reserve(x_r.size());
  for (size_t i = 0; i < x_r.size(); ++i) {
    InverseDepthSample p;
    if (!PairInverseDepth(x_r[i], x_n[i], R, t, sigma, &p.s, &p.sigma) || !std::isfinite(p.s) ||
        !std::isfinite(p.sigma)) {
      continue;
    }
    p.ray = x_r[i].homogeneous();
    p.tolerance = o.inlier_sigmas * p.sigma + o.inlier_rel * std::abs(p.s);
    if (p.s <= 0.0 || p.sigma > o.max_rel_sigma * p.s) {
      imprecise.push_back(p);
      continue;
    }
    const Eigen::Vector3d a = R * p.ray;
    p.parallax_px = (x_n[i] - a.hnormalized()).norm() * focal_px;
    pts.push_back(p);
  }
  const int candidates = static_cast<int>(pts.size());
  const int needed = std::max(o.min_inliers, static_cast<int>(std::ceil(o.min_inlier_share * candidates)));
  if (candidates < needed || candidates < 3) return std::nullopt;

  std::mt19937 rng(static_cast<unsigned>(o.seed));
  std::uniform_int_distribution<int> pick(0, candidates - 1);
  // MSAC with a local optimisation: a minimal sample's plane is too coarse to judge
  // whether tracks lie beyond it, so promising hypotheses are refitted on their inliers
  // first and judged after; among qualified planes the one that fits best wins.
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  PlaneScore best_score;
  best_score.cost = std::numeric_limits<double>::infinity();
  int iterations = o.ransac_iterations;
  for (int it = 0; it < iterations; ++it) {
    const int i = pick(rng), j = pick(rng), k = pick(rng);
    if (i == j || j == k || i == k) continue;
    Eigen::Matrix3d A;
    A.row(0) = pts[i].ray.transpose();
    A.row(1) = pts[j].ray.transpose();
    A.row(2) = pts[k].ray.transpose();
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
    if (!lu.isInvertible()) continue;
    Eigen::Vector3d m = lu.solve(Eigen::Vector3d(pts[i].s, pts[j].s, pts[k].s));
    if (!m.allFinite() || TiltDeg(m) > o.max_tilt_deg) continue;
    const PlaneScore raw = Score(pts, nullptr, m, o);
    if (raw.inliers < needed || raw.cost >= best_score.cost + needed) continue;
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::Vector3d refit = m;
      if (!Refit(pts, o, &refit) || TiltDeg(refit) > o.max_tilt_deg) break;
      m = refit;
    }
    const PlaneScore score = Score(pts, &imprecise, m, o);
    if (score.qualified && score.inliers >= needed && score.cost < best_score.cost) {
      best_score = score;
      best = m;
      // Enough hypotheses for three inliers drawn at least once with 99 % confidence.
      const double w = static_cast<double>(score.inliers) / candidates;
      const double miss = 1.0 - w * w * w;
      if (miss <= 0.0) {
        iterations = it + 1;
      } else if (miss < 1.0) {
        const double needed_more = std::ceil(std::log(0.01) / std::log(miss));
        iterations = std::min(iterations, it + 1 + static_cast<int>(std::min<double>(needed_more, iterations)));
      }
    }
  }
  if (!best_score.qualified) return std::nullopt;
  PairGroundPlane plane;
  plane.m = best;
  plane.candidates = candidates;
  std::vector<double> parallax;
  for (const InverseDepthSample& p : pts) {
    if (!IsInlier(p, best)) continue;
    ++plane.inliers;
    parallax.push_back(p.parallax_px);
  }
  if (plane.inliers < needed) return std::nullopt;
  std::nth_element(parallax.begin(), parallax.begin() + parallax.size() / 2, parallax.end());
  plane.median_parallax_px = parallax[parallax.size() / 2];
  if (plane.median_parallax_px < o.min_parallax_px) return std::nullopt;
  return plane;
}

DepthBound CapDepthByGround(const PairGroundPlane& plane, const Eigen::Vector2d& x_r, DepthBound bound,
                            const PairGroundOptions& o) {
  const Eigen::Vector3d ray = x_r.homogeneous();
  const double s_ray = plane.m.dot(ray);  // inverse depth where the ray meets the plane
  const double mn = plane.m.norm();
  if (s_ray <= 0.0 || mn <= 0.0) return bound;
  // Angle of the ray below the plane's horizon.
  const double elevation = std::asin(std::clamp(s_ray / (mn * ray.norm()), -1.0, 1.0));
  if (elevation < o.depth_bound_min_elevation_deg * M_PI / 180.0) return bound;
  const double cap = GroundDepthCap(1.0 / s_ray, elevation, o.depth_bound_margin, o.depth_bound_tilt_sigma_deg);
  bound.z_max = std::min(bound.z_max, cap);
  if (bound.z_min > bound.z_max) bound.z_min = 0.0;
  return bound;
}

}  // namespace mbslam
