#include "services/perception/slam/cost_functions/reprojection_error.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/rotation.h>

namespace mbslam {
namespace {

struct ReprojectionErrorFunctor {
  ReprojectionErrorFunctor(const Eigen::Vector2d& xy, double focal) : xy_(xy), focal_(focal) {}

  template <typename T>
  bool operator()(const T* q, const T* t, const T* X, T* residual) const {
    // Eigen order (x, y, z, w) -> Ceres order (w, x, y, z).
    const T q_wxyz[4] = {q[3], q[0], q[1], q[2]};
    T p[3];
    ceres::UnitQuaternionRotatePoint(q_wxyz, X, p);
    p[0] += t[0];
    p[1] += t[1];
    p[2] += t[2];
    if (p[2] <= T(1e-9)) {
      residual[0] = T(0);
      residual[1] = T(0);
      return false;
    }
    residual[0] = T(focal_) * (p[0] / p[2] - T(xy_.x()));
    residual[1] = T(focal_) * (p[1] / p[2] - T(xy_.y()));
    return true;
  }

  const Eigen::Vector2d xy_;
  const double focal_;
};

struct OdometryTranslationPriorFunctor {
  OdometryTranslationPriorFunctor(const Eigen::Vector3d& d, double sigma) : d_(d), sigma_(sigma) {}

  template <typename T>
  bool operator()(const T* qa, const T* ta, const T* qb, const T* tb, T* residual) const {
    const T qa_wxyz[4] = {qa[3], qa[0], qa[1], qa[2]};
    const T qb_inv[4] = {qb[3], -qb[0], -qb[1], -qb[2]};
    const T qa_inv[4] = {qa[3], -qa[0], -qa[1], -qa[2]};
    T ca[3], cb[3];
    ceres::UnitQuaternionRotatePoint(qa_inv, ta, ca);
    ceres::UnitQuaternionRotatePoint(qb_inv, tb, cb);
    // c = -R^T t
    const T diff[3] = {-(cb[0]) + ca[0], -(cb[1]) + ca[1], -(cb[2]) + ca[2]};
    T d_in_a[3];
    ceres::UnitQuaternionRotatePoint(qa_wxyz, diff, d_in_a);
    for (int i = 0; i < 3; ++i) residual[i] = (d_in_a[i] - T(d_[i])) / T(sigma_);
    return true;
  }

  const Eigen::Vector3d d_;
  const double sigma_;
};

struct RelativeRotationPriorFunctor {
  RelativeRotationPriorFunctor(const Eigen::Quaterniond& b_from_a, double sigma)
      : inv_wxyz_{b_from_a.w(), -b_from_a.x(), -b_from_a.y(), -b_from_a.z()}, sigma_(sigma) {}

  template <typename T>
  bool operator()(const T* qa, const T* qb, T* residual) const {
    const T qa_inv[4] = {qa[3], -qa[0], -qa[1], -qa[2]};
    const T qb_wxyz[4] = {qb[3], qb[0], qb[1], qb[2]};
    const T expected_inv[4] = {T(inv_wxyz_[0]), T(inv_wxyz_[1]), T(inv_wxyz_[2]), T(inv_wxyz_[3])};
    T ba[4], e[4];
    ceres::QuaternionProduct(qb_wxyz, qa_inv, ba);
    ceres::QuaternionProduct(ba, expected_inv, e);
    // The error rotation and its negative are the same rotation: take the short way.
    const T sign = e[0] < T(0) ? T(-1) : T(1);
    for (int i = 0; i < 3; ++i) residual[i] = T(2) * sign * e[i + 1] / T(sigma_);
    return true;
  }

  const double inv_wxyz_[4];
  const double sigma_;
};

}  // namespace

ceres::CostFunction* CreateRelativeRotationPrior(const Eigen::Quaterniond& b_from_a, double sigma_rad) {
  return new ceres::AutoDiffCostFunction<RelativeRotationPriorFunctor, 3, 4, 4>(
      new RelativeRotationPriorFunctor(b_from_a.normalized(), sigma_rad));
}

ceres::CostFunction* CreateReprojectionError(const Eigen::Vector2d& xy, double focal_px) {
  return new ceres::AutoDiffCostFunction<ReprojectionErrorFunctor, 2, 4, 3, 3>(
      new ReprojectionErrorFunctor(xy, focal_px));
}

ceres::CostFunction* CreateOdometryTranslationPrior(const Eigen::Vector3d& d_ab_in_a, double sigma_m) {
  return new ceres::AutoDiffCostFunction<OdometryTranslationPriorFunctor, 3, 4, 3, 4, 3>(
      new OdometryTranslationPriorFunctor(d_ab_in_a, sigma_m));
}

}  // namespace mbslam
