#include "tools/eval/alignment.h"

#include <Eigen/SVD>

#include <cmath>

namespace mbslam {
namespace eval {

Status UmeyamaAlignment(const std::vector<Eigen::Vector3d>& src,
                        const std::vector<Eigen::Vector3d>& dst, bool with_scale,
                        Sim3d* dst_from_src) {
  if (src.size() != dst.size()) {
    return Status::Error("alignment: point sets differ in size");
  }
  if (src.size() < 3) {
    return Status::Error("alignment: needs at least 3 point pairs, got " +
                         std::to_string(src.size()));
  }
  const double n = static_cast<double>(src.size());
  Eigen::Vector3d mu_src = Eigen::Vector3d::Zero(), mu_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    mu_src += src[i];
    mu_dst += dst[i];
  }
  mu_src /= n;
  mu_dst /= n;
  // Cross-covariance Sigma = 1/n sum (dst - mu_dst)(src - mu_src)^T and source variance.
  Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
  double var_src = 0.0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Eigen::Vector3d s = src[i] - mu_src;
    sigma += (dst[i] - mu_dst) * s.transpose();
    var_src += s.squaredNorm();
  }
  sigma /= n;
  var_src /= n;
  if (!(var_src > 1e-24)) {
    return Status::Error("alignment: the source points all coincide");
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(sigma, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d& d = svd.singularValues();
  if (d(1) <= 1e-12 * std::max(1.0, d(0))) {
    return Status::Error("alignment: the points are (nearly) collinear, rotation undetermined");
  }
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) {
    S(2, 2) = -1.0;
  }
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  const double scale = with_scale ? (d.asDiagonal() * S).trace() / var_src : 1.0;
  dst_from_src->scale = scale;
  dst_from_src->rotation = Eigen::Quaterniond(R).normalized();
  dst_from_src->translation = mu_dst - scale * (R * mu_src);
  return Status::Ok();
}

Status OrientationAlignment(const std::vector<Rigid3d>& src, const std::vector<Rigid3d>& dst,
                            bool with_scale, Sim3d* dst_from_src) {
  if (src.size() != dst.size()) return Status::Error("alignment: pose sets differ in size");
  if (src.size() < 2) return Status::Error("alignment: needs at least 2 poses");
  Eigen::Matrix3d m = Eigen::Matrix3d::Zero();
  Eigen::Vector3d mu_src = Eigen::Vector3d::Zero(), mu_dst = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < src.size(); ++i) {
    m += dst[i].rotation.toRotationMatrix() * src[i].rotation.toRotationMatrix().transpose();
    mu_src += src[i].translation;
    mu_dst += dst[i].translation;
  }
  const double n = static_cast<double>(src.size());
  mu_src /= n;
  mu_dst /= n;
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0.0) S(2, 2) = -1.0;
  const Eigen::Matrix3d R = svd.matrixU() * S * svd.matrixV().transpose();
  double num = 0.0, den = 0.0;
  for (size_t i = 0; i < src.size(); ++i) {
    const Eigen::Vector3d a = R * (src[i].translation - mu_src);
    num += (dst[i].translation - mu_dst).dot(a);
    den += a.squaredNorm();
  }
  double scale = 1.0;
  if (with_scale) {
    if (!(den > 1e-24)) return Status::Error("alignment: the source positions all coincide");
    scale = num / den;
    if (!(scale > 0.0)) return Status::Error("alignment: non-positive scale from the orientations");
  }
  dst_from_src->scale = scale;
  dst_from_src->rotation = Eigen::Quaterniond(R).normalized();
  dst_from_src->translation = mu_dst - scale * (R * mu_src);
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
