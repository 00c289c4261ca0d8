#include "services/perception/geometry/rigid3.h"

#include <cmath>

namespace mbslam {
namespace {
constexpr double kSmallAngle = 1e-8;
}  // namespace

Eigen::Matrix3d Hat(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  if (theta < kSmallAngle) return Eigen::Matrix3d::Identity() + Hat(w);
  return Eigen::AngleAxisd(theta, w / theta).toRotationMatrix();
}

Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R) {
  Eigen::AngleAxisd aa(R);
  double angle = aa.angle();
  Eigen::Vector3d axis = aa.axis();
  if (angle > M_PI) {
    angle = 2.0 * M_PI - angle;
    axis = -axis;
  }
  if (angle < kSmallAngle) {
    // First order: R ~ I + Hat(w).
    return Eigen::Vector3d(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1)) * 0.5;
  }
  return angle * axis;
}

Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = Hat(w);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / t2 * W +
         (theta - std::sin(theta)) / (t2 * theta) * W * W;
}

Eigen::Matrix3d LeftJacobianInverseSO3(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  const Eigen::Matrix3d W = Hat(w);
  if (theta < 1e-5) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 12.0;
  const double half = 0.5 * theta;
  const double cot = std::cos(half) / std::sin(half);
  return Eigen::Matrix3d::Identity() - 0.5 * W +
         (1.0 / (theta * theta)) * (1.0 - half * cot) * W * W;
}

Eigen::Matrix4d Rigid3d::ToMatrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = RotationMatrix();
  m.topRightCorner<3, 1>() = translation;
  return m;
}

Eigen::Matrix<double, 3, 4> Rigid3d::ToMatrix3x4() const {
  Eigen::Matrix<double, 3, 4> m;
  m.leftCols<3>() = RotationMatrix();
  m.col(3) = translation;
  return m;
}

Rigid3d Rigid3d::Exp(const Vector6d& xi) {
  const Eigen::Vector3d v = xi.head<3>();
  const Eigen::Vector3d w = xi.tail<3>();
  return Rigid3d(Eigen::Matrix3d(ExpSO3(w)), Eigen::Vector3d(LeftJacobianSO3(w) * v));
}

Vector6d Rigid3d::Log() const {
  const Eigen::Vector3d w = LogSO3(RotationMatrix());
  Vector6d xi;
  xi.head<3>() = LeftJacobianInverseSO3(w) * translation;
  xi.tail<3>() = w;
  return xi;
}

Matrix6d Rigid3d::Adjoint() const {
  const Eigen::Matrix3d R = RotationMatrix();
  Matrix6d ad = Matrix6d::Zero();
  ad.topLeftCorner<3, 3>() = R;
  ad.topRightCorner<3, 3>() = Hat(translation) * R;
  ad.bottomRightCorner<3, 3>() = R;
  return ad;
}

Rigid3d Rigid3d::Interpolate(const Rigid3d& a, const Rigid3d& b, double t) {
  const Rigid3d delta = a.Inverse() * b;
  return a * Exp(t * delta.Log());
}

double RotationDistance(const Rigid3d& a, const Rigid3d& b) {
  return a.rotation.angularDistance(b.rotation);
}

double TranslationDistance(const Rigid3d& a, const Rigid3d& b) {
  return (a.translation - b.translation).norm();
}

Sim3d Sim3d::Inverse() const {
  Sim3d inv;
  inv.scale = 1.0 / scale;
  inv.rotation = rotation.conjugate();
  inv.translation = -(inv.scale * (inv.rotation * translation));
  return inv;
}

}  // namespace mbslam
