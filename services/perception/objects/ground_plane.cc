#include "services/perception/objects/ground_plane.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "services/perception/objects/random.h"

namespace mbslam {

bool GroundPlane::IsValid() const {
  return normal.allFinite() && std::isfinite(offset) && std::abs(normal.norm() - 1.0) < 1e-6;
}

Eigen::Vector4d GroundPlane::ToVector4() const {
  Eigen::Vector4d v;
  v << normal, offset;
  return v;
}

std::optional<GroundPlane> GroundPlane::FromVector4(const Eigen::Vector4d& plane) {
  if (!plane.allFinite()) return std::nullopt;
  const double n = plane.head<3>().norm();
  if (n < 1e-12) return std::nullopt;
  GroundPlane g;
  g.normal = plane.head<3>() / n;
  g.offset = plane[3] / n;
  return g;
}

namespace {

// Orthonormal basis (columns) of the directions perpendicular to `in_plane`.
Eigen::MatrixXd NormalSpace(const std::vector<Eigen::Vector3d>& in_plane) {
  std::vector<Eigen::Vector3d> basis;  // Gram-Schmidt of the in-plane directions
  for (const Eigen::Vector3d& d : in_plane) {
    Eigen::Vector3d v = d;
    for (const Eigen::Vector3d& b : basis) v -= b.dot(v) * b;
    if (v.allFinite() && v.norm() > 1e-9 * std::max(1.0, d.norm())) basis.push_back(v.normalized());
    if (basis.size() == 2) break;
  }
  Eigen::Matrix3d P = Eigen::Matrix3d::Identity();
  for (const Eigen::Vector3d& b : basis) P -= b * b.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(P);  // eigenvalues 0 (in plane) or 1
  const int k = 3 - static_cast<int>(basis.size());
  return eig.eigenvectors().rightCols(k);
}

// Least-squares plane through `points[indices]`, normal oriented along `up` and within the
// span of `Q`'s columns.
bool FitPlane(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
              const Eigen::Vector3d& up, const Eigen::MatrixXd& Q, GroundPlane* plane) {
  if (indices.size() < 3) return false;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : indices) mean += points[static_cast<size_t>(i)];
  mean /= static_cast<double>(indices.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : indices) {
    const Eigen::Vector3d d = points[static_cast<size_t>(i)] - mean;
    cov += d * d.transpose();
  }
  const Eigen::MatrixXd reduced = Q.transpose() * cov * Q;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(reduced);
  if (eig.info() != Eigen::Success) return false;
  Eigen::Vector3d n = Q * eig.eigenvectors().col(0);  // smallest eigenvalue first
  if (!n.allFinite() || n.norm() < 1e-12) return false;
  n.normalize();
  if (n.dot(up) < 0.0) n = -n;
  plane->normal = n;
  plane->offset = -n.dot(mean);
  return true;
}

void CollectInliers(const std::vector<Eigen::Vector3d>& points, const GroundPlane& plane,
                    double threshold, std::vector<int>* inliers) {
  inliers->clear();
  for (size_t i = 0; i < points.size(); ++i) {
    if (std::abs(plane.Height(points[i])) <= threshold) inliers->push_back(static_cast<int>(i));
  }
}

// Share of the finite points within `threshold` of `plane` [0, 1].
double Support(const std::vector<Eigen::Vector3d>& points, const GroundPlane& plane, double threshold) {
  int n = 0, in = 0;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    ++n;
    in += std::abs(plane.Height(p)) <= threshold;
  }
  return n > 0 ? static_cast<double>(in) / n : 0.0;
}

}  // namespace

Status EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Vector3d& up_hint, const GroundPlaneOptions& options,
                           GroundPlaneEstimate* estimate) {
  return EstimateGroundPlane(points, up_hint, options, {}, estimate);
}

std::vector<Eigen::Vector3d> SpreadDirections(const std::vector<Eigen::Vector3d>& centres,
                                              const Eigen::Vector3d& up, double max_tilt_deg,
                                              double min_spread) {
  std::vector<Eigen::Vector3d> out;
  if (centres.size() < 2 || !up.allFinite() || up.norm() < 1e-12) return out;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : centres) mean += c;
  mean /= static_cast<double>(centres.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& c : centres) cov += (c - mean) * (c - mean).transpose();
  cov /= static_cast<double>(centres.size());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success) return out;
  const double sin_tilt = std::sin(max_tilt_deg * M_PI / 180.0);
  for (int k = 2; k >= 0; --k) {  // largest spread first
    const double spread = std::sqrt(std::max(0.0, eig.eigenvalues()[k]));
    if (!(spread >= min_spread)) break;
    const Eigen::Vector3d d = eig.eigenvectors().col(k);
    if (std::abs(d.dot(up.normalized())) <= sin_tilt) out.push_back(d);
  }
  return out;
}

double SpreadAlong(const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& direction) {
  if (centres.empty()) return 0.0;
  double mean = 0.0;
  for (const Eigen::Vector3d& c : centres) mean += c.dot(direction);
  mean /= static_cast<double>(centres.size());
  double var = 0.0;
  for (const Eigen::Vector3d& c : centres) var += (c.dot(direction) - mean) * (c.dot(direction) - mean);
  return std::sqrt(var / static_cast<double>(centres.size()));
}

Status EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Vector3d& up_hint, const GroundPlaneOptions& options,
                           const std::vector<Eigen::Vector3d>& in_plane_directions,
                           GroundPlaneEstimate* estimate) {
  if (estimate == nullptr) return Status::Error("EstimateGroundPlane: null output");
  if (!options.Check()) return Status::Error("ground plane options: " + LastOptionError());
  if (!up_hint.allFinite() || up_hint.norm() < 1e-12) {
    return Status::Error("EstimateGroundPlane: the up hint is zero or not finite");
  }
  const Eigen::Vector3d up = up_hint.normalized();
  std::vector<Eigen::Vector3d> finite;
  finite.reserve(points.size());
  for (const Eigen::Vector3d& p : points) {
    if (p.allFinite()) finite.push_back(p);
  }
  const int n = static_cast<int>(finite.size());
  if (n < 3) {
    return Status::Error("EstimateGroundPlane: " + std::to_string(n) + " finite points, need 3");
  }
  const double cos_tilt = std::cos(options.max_tilt_deg * M_PI / 180.0);
  const Eigen::MatrixXd Q = NormalSpace(in_plane_directions);
  const bool constrained = Q.cols() < 3;
  ParticleRng rng(static_cast<uint64_t>(options.seed));

  int best_count = 0;
  double best_score = 0.0;
  GroundPlane best;
  for (int it = 0; it < options.max_iterations; ++it) {
    const int a = static_cast<int>(rng.Uniform() * n);
    const int b = static_cast<int>(rng.Uniform() * n);
    const int c = static_cast<int>(rng.Uniform() * n);
    if (a == b || b == c || a == c) continue;
    const Eigen::Vector3d& pa = finite[static_cast<size_t>(a)];
    Eigen::Vector3d normal =
        (finite[static_cast<size_t>(b)] - pa).cross(finite[static_cast<size_t>(c)] - pa);
    if (constrained) normal = Q * (Q.transpose() * normal);
    const double norm = normal.norm();
    if (norm < 1e-12) continue;
    normal /= norm;
    if (normal.dot(up) < 0.0) normal = -normal;
    if (normal.dot(up) < cos_tilt) continue;
    GroundPlane hypothesis;
    hypothesis.normal = normal;
    hypothesis.offset = -normal.dot(pa);
    // MSAC-like score: inliers count with a bonus for being close to the plane.
    int count = 0;
    double score = 0.0;
    const double t2 = options.inlier_threshold * options.inlier_threshold;
    for (const Eigen::Vector3d& p : finite) {
      const double h = hypothesis.Height(p);
      if (h * h <= t2) {
        ++count;
        score += 1.0 - h * h / t2;
      }
    }
    if (score > best_score) {
      best_score = score;
      best_count = count;
      best = hypothesis;
    }
  }
  if (best_count < 3) return Status::Error("EstimateGroundPlane: no near-horizontal plane found");

  std::vector<int> inliers;
  CollectInliers(finite, best, options.inlier_threshold, &inliers);
  for (int r = 0; r < options.refine_iterations; ++r) {
    GroundPlane refined;
    if (!FitPlane(finite, inliers, up, Q, &refined)) break;
    if (refined.normal.dot(up) < cos_tilt) break;
    std::vector<int> next;
    CollectInliers(finite, refined, options.inlier_threshold, &next);
    if (next.size() < inliers.size()) break;  // the refit lost support: keep the previous
    best = refined;
    inliers.swap(next);
  }
  const int count = static_cast<int>(inliers.size());
  const double ratio = static_cast<double>(count) / static_cast<double>(n);
  if (count < options.min_inliers || ratio < options.min_inlier_ratio) {
    return Status::Error("EstimateGroundPlane: best plane has " + std::to_string(count) +
                         " inliers of " + std::to_string(n) + " points");
  }
  double sq = 0.0;
  for (int i : inliers) {
    const double h = best.Height(finite[static_cast<size_t>(i)]);
    sq += h * h;
  }
  estimate->plane = best;
  estimate->num_inliers = count;
  estimate->inlier_ratio = ratio;
  estimate->rms = std::sqrt(sq / static_cast<double>(count));
  return Status::Ok();
}

namespace {

// Share of the finite points more than `band` below the plane.
double BelowShare(const std::vector<Eigen::Vector3d>& points, const GroundPlane& plane, double band) {
  int n = 0, below = 0;
  for (const Eigen::Vector3d& p : points) {
    if (!p.allFinite()) continue;
    ++n;
    below += plane.Height(p) < -band;
  }
  return n > 0 ? static_cast<double>(below) / static_cast<double>(n) : 0.0;
}

Status FitAlongTravel(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up_hint,
                      const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& camera,
                      const GroundPlaneOptions& options, GroundPlaneEstimate* estimate, bool* along_travel);

}  // namespace

Status EstimateGroundPlaneAlongTravel(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up_hint,
                                      const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& camera,
                                      const GroundPlaneOptions& options, GroundPlaneEstimate* estimate,
                                      bool* along_travel) {
  if (estimate == nullptr || along_travel == nullptr) return Status::Error("EstimateGroundPlaneAlongTravel: null output");
  MBSLAM_RETURN_IF_ERROR(FitAlongTravel(points, up_hint, centres, camera, options, estimate, along_travel));
  const double below = BelowShare(points, estimate->plane, options.inlier_threshold);
  if (below > options.max_below_share) {
    *along_travel = false;
    return Status::Error("EstimateGroundPlaneAlongTravel: " + std::to_string(below) +
                         " of the points lie below the plane, above max_below_share");
  }
  return Status::Ok();
}

namespace {

Status FitAlongTravel(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& up_hint,
                      const std::vector<Eigen::Vector3d>& centres, const Eigen::Vector3d& camera,
                      const GroundPlaneOptions& options, GroundPlaneEstimate* estimate, bool* along_travel) {
  *along_travel = false;
  GroundPlaneEstimate free_fit;
  Status status = EstimateGroundPlane(points, up_hint, options, &free_fit);
  if (!status.ok()) return status;
  if (free_fit.inlier_ratio < options.min_support) {
    return Status::Error("EstimateGroundPlaneAlongTravel: the plane holds " + std::to_string(free_fit.inlier_ratio) +
                         " of the points, below min_support");
  }
  *estimate = free_fit;
  double h = free_fit.plane.Height(camera);
  if (!(h > 0.0)) {
    return Status::Error("EstimateGroundPlaneAlongTravel: the camera is " + std::to_string(-h) + " below the plane");
  }
  // The band in camera heights: a band wide against the camera's height takes in what
  // stands on the ground, and the plane fitted to it rises above the ground. Support
  // (min_support) stays measured in the world-unit band.
  GroundPlaneOptions narrowed = options;
  const double band = options.inlier_threshold_camera_heights * h;
  if (band > 0.0 && band < options.inlier_threshold) {
    narrowed.inlier_threshold = band;
    GroundPlaneEstimate refit;
    if (EstimateGroundPlane(points, up_hint, narrowed, &refit).ok() && refit.plane.Height(camera) > 0.0) {
      free_fit = refit;
      *estimate = refit;
      h = refit.plane.Height(camera);
    }
  }
  if (centres.empty() || options.path_parallel_min_spread <= 0.0) return Status::Ok();
  const double min_spread = options.path_parallel_min_spread;
  // Near-horizontal directions of travel, the longest first: those long enough against
  // the camera's height above the free fit, or else the longest alone (short travel).
  std::vector<Eigen::Vector3d> directions = SpreadDirections(centres, free_fit.plane.normal, options.max_tilt_deg, 0.0);
  if (directions.empty()) return Status::Ok();
  const bool short_travel = SpreadAlong(centres, directions.front()) < min_spread * h;
  if (short_travel) {
    directions.resize(1);
  } else {
    while (SpreadAlong(centres, directions.back()) < min_spread * h) directions.pop_back();
  }
  GroundPlaneEstimate constrained;
  bool use_constrained = EstimateGroundPlane(points, up_hint, narrowed, directions, &constrained).ok() &&
                         Support(points, constrained.plane, options.inlier_threshold) >= options.min_support;
  const double hc = constrained.plane.Height(camera);
  if (use_constrained) use_constrained = hc > 0.0;
  if (use_constrained && short_travel) use_constrained = SpreadAlong(centres, directions.front()) >= min_spread * hc;
  if (use_constrained) {
    *estimate = constrained;
    *along_travel = true;
    return Status::Ok();
  }
  // No plane along the travel: the free fit stays only if the travel does not contradict
  // it (a camera that rides at a constant height moves parallel to the ground).
  const double tilt = std::asin(std::min(1.0, std::abs(free_fit.plane.normal.dot(directions.front().normalized()))));
  if (tilt > options.max_travel_tilt_deg * M_PI / 180.0) {
    return Status::Error("EstimateGroundPlaneAlongTravel: the plane is tilted " + std::to_string(tilt * 180.0 / M_PI) +
                         " deg from the camera's travel");
  }
  return Status::Ok();
}

}  // namespace

Status EstimateGroundPlane(const std::vector<Eigen::Vector3d>& points,
                           const Eigen::Vector3d& up_hint, GroundPlaneEstimate* estimate) {
  return EstimateGroundPlane(points, up_hint, GroundPlaneOptions(), estimate);
}

}  // namespace mbslam
