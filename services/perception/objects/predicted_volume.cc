#include "services/perception/objects/predicted_volume.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>

namespace mbslam {
namespace {

constexpr double kMinScale = 1e-9;

// Value at quantile q in [0, 1] of `values` (reorders them).
double Quantile(std::vector<double>* values, double q) {
  const size_t n = values->size();
  const size_t k = std::min(
      n - 1, static_cast<size_t>(std::ceil(q * static_cast<double>(n))) - (q > 0.0 ? 1 : 0));
  std::nth_element(values->begin(), values->begin() + static_cast<std::ptrdiff_t>(k),
                   values->end());
  return (*values)[k];
}

// Right-handed axes from the cloud's covariance: principal directions, or with a known
// up direction the principal horizontal direction, its horizontal normal and up.
Eigen::Matrix3d BoxAxes(const Eigen::Matrix3d& cov, const std::optional<Eigen::Vector3d>& up) {
  Eigen::Matrix3d axes;
  if (up) {
    const Eigen::Vector3d z = up->normalized();
    // Any horizontal basis, then the principal direction within it.
    Eigen::Vector3d h1 = z.unitOrthogonal();
    Eigen::Vector3d h2 = z.cross(h1);
    Eigen::Matrix2d c2;
    c2 << h1.dot(cov * h1), h1.dot(cov * h2), h2.dot(cov * h1), h2.dot(cov * h2);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(c2);
    Eigen::Vector2d major = eig.eigenvectors().col(1);
    if (!major.allFinite() || eig.eigenvalues()(1) <= kMinScale * kMinScale) {
      major = Eigen::Vector2d::UnitX();
    }
    Eigen::Vector3d x = (major.x() * h1 + major.y() * h2).normalized();
    // Deterministic sign: the largest component positive.
    Eigen::Index i;
    x.cwiseAbs().maxCoeff(&i);
    if (x[i] < 0.0) x = -x;
    axes << x, z.cross(x), z;
    return axes;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success || !eig.eigenvectors().allFinite() ||
      eig.eigenvalues()(2) <= kMinScale * kMinScale) {
    return Eigen::Matrix3d::Identity();
  }
  Eigen::Vector3d x = eig.eigenvectors().col(2);
  Eigen::Vector3d y = eig.eigenvectors().col(1);
  for (Eigen::Vector3d* a : {&x, &y}) {
    Eigen::Index i;
    a->cwiseAbs().maxCoeff(&i);
    if ((*a)[i] < 0.0) *a = -*a;
  }
  axes << x, y, x.cross(y);
  return axes;
}

}  // namespace

bool PredictedVolume::Contains(const Eigen::Vector3d& point_in_world) const {
  const Eigen::Vector3d local = orientation.conjugate() * (point_in_world - center);
  return (local.cwiseAbs().array() <= half_extent.array()).all();
}

PredictedVolume BoundingVolume(const std::vector<Eigen::Vector3d>& centers,
                               const std::optional<Eigen::Vector3d>& up, const ObjectExtent& extent,
                               double probability, double margin) {
  PredictedVolume volume;
  const size_t n = centers.size();
  if (n == 0) return volume;
  probability = std::clamp(probability, 0.0, 1.0);

  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& c : centers) mean += c;
  mean /= static_cast<double>(n);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& c : centers) cov += (c - mean) * (c - mean).transpose();
  cov /= static_cast<double>(n);
  const Eigen::Matrix3d axes = BoxAxes(cov, up);

  // Coordinates along the axes; per axis a robust centre and scale.
  std::vector<Eigen::Vector3d> local(n);
  for (size_t i = 0; i < n; ++i) local[i] = axes.transpose() * (centers[i] - mean);
  Eigen::Vector3d mid, scale;
  std::vector<double> values(n);
  const double q_lo = 0.5 * (1.0 - probability), q_hi = 0.5 * (1.0 + probability);
  for (int k = 0; k < 3; ++k) {
    for (size_t i = 0; i < n; ++i) values[i] = local[i][k];
    const double lo = Quantile(&values, q_lo);
    const double hi = Quantile(&values, q_hi);
    mid[k] = 0.5 * (lo + hi);
    scale[k] = std::max(0.5 * (hi - lo), kMinScale);
  }
  std::vector<double> radius(n);
  for (size_t i = 0; i < n; ++i) {
    radius[i] = ((local[i] - mid).cwiseAbs().array() / scale.array()).maxCoeff();
  }
  std::vector<double> sorted = radius;
  const double r = Quantile(&sorted, probability);
  size_t inside = 0;
  for (double x : radius) inside += x <= r ? 1 : 0;

  // (A hair wider, so that the particle on the boundary stays inside after rounding.)
  const Eigen::Vector3d core = (r * (1.0 + 1e-9)) * scale;
  volume.center =
      mean + axes * mid + (extent.valid ? extent.center_offset : Eigen::Vector3d::Zero());
  volume.orientation = Eigen::Quaterniond(axes).normalized();
  volume.half_extent =
      core + extent.HalfSizeAlong(axes) + Eigen::Vector3d::Constant(std::max(margin, 0.0));
  volume.probability = static_cast<double>(inside) / static_cast<double>(n);
  return volume;
}

}  // namespace mbslam
