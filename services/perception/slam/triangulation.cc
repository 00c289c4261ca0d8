#include "services/perception/slam/triangulation.h"

#include <cmath>
#include <limits>

#include <Eigen/SVD>

namespace mbslam {

std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3d& Ta, const Eigen::Vector2d& xa,
                                              const Rigid3d& Tb, const Eigen::Vector2d& xb) {
  const Eigen::Matrix<double, 3, 4> Pa = Ta.ToMatrix3x4();
  const Eigen::Matrix<double, 3, 4> Pb = Tb.ToMatrix3x4();
  Eigen::Matrix4d A;
  A.row(0) = xa.x() * Pa.row(2) - Pa.row(0);
  A.row(1) = xa.y() * Pa.row(2) - Pa.row(1);
  A.row(2) = xb.x() * Pb.row(2) - Pb.row(0);
  A.row(3) = xb.y() * Pb.row(2) - Pb.row(1);
  Eigen::JacobiSVD<Eigen::Matrix4d> svd(A, Eigen::ComputeFullV);
  const Eigen::Vector4d X = svd.matrixV().col(3);
  if (std::abs(X.w()) < 1e-12) return std::nullopt;
  const Eigen::Vector3d p = X.head<3>() / X.w();
  if (!p.allFinite()) return std::nullopt;
  return p;
}

double ParallaxAngle(const Rigid3d& Ta, const Rigid3d& Tb, const Eigen::Vector3d& X) {
  const Eigen::Vector3d ca = Ta.Inverse().translation;
  const Eigen::Vector3d cb = Tb.Inverse().translation;
  const Eigen::Vector3d ra = (X - ca).normalized();
  const Eigen::Vector3d rb = (X - cb).normalized();
  return std::acos(std::clamp(ra.dot(rb), -1.0, 1.0));
}

double ReprojectionError(const Rigid3d& T, const Eigen::Vector3d& X, const Eigen::Vector2d& xy) {
  const Eigen::Vector3d p = T * X;
  if (p.z() <= 1e-9) return std::numeric_limits<double>::infinity();
  return (p.hnormalized() - xy).norm();
}

bool ProjectionJacobians(const Rigid3d& T, const Eigen::Vector3d& X, Eigen::Vector2d* projection,
                         Eigen::Matrix<double, 2, 6>* d_pose, Eigen::Matrix<double, 2, 3>* d_point) {
  const Eigen::Vector3d p = T * X;
  if (p.z() <= 1e-9) return false;
  const double iz = 1.0 / p.z();
  const Eigen::Vector2d x(p.x() * iz, p.y() * iz);
  if (projection) *projection = x;
  Eigen::Matrix<double, 2, 3> dx_dp;
  dx_dp << iz, 0.0, -x.x() * iz, 0.0, iz, -x.y() * iz;
  if (d_pose) {
    // p' = Exp(xi) p ~ p + v + w x p  =>  dp/dxi = [I, -[p]x]
    Eigen::Matrix<double, 3, 6> dp_dxi;
    dp_dxi.leftCols<3>() = Eigen::Matrix3d::Identity();
    dp_dxi.rightCols<3>() = -Hat(p);
    *d_pose = dx_dp * dp_dxi;
  }
  if (d_point) *d_point = dx_dp * T.RotationMatrix();
  return true;
}

}  // namespace mbslam
