#include "services/perception/slam/pose_estimator.h"

#include <cmath>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "services/perception/slam/triangulation.h"

namespace mbslam {

Rigid3d RefinePose(const Rigid3d& initial, const std::vector<Eigen::Vector3d>& X,
                   const std::vector<Eigen::Vector2d>& xy, const std::vector<uint8_t>& use,
                   double focal, double huber_px, int iterations, Matrix6d* information,
                   const PoseRotationPrior* rotation_prior, double sigma_px) {
  Rigid3d T = initial;
  const double huber = huber_px / focal;
  const Eigen::Matrix3d prior_target_t =
      rotation_prior ? Eigen::Matrix3d(rotation_prior->cam_from_world.toRotationMatrix().transpose())
                     : Eigen::Matrix3d::Identity();
  const double prior_weight =
      rotation_prior ? std::pow(sigma_px / (focal * rotation_prior->sigma_rad), 2) : 0.0;
  Matrix6d H = Matrix6d::Zero();
  for (int iter = 0; iter < iterations; ++iter) {
    H.setZero();
    Vector6d g = Vector6d::Zero();
    int n = 0;
    for (size_t i = 0; i < X.size(); ++i) {
      if (!use[i]) continue;
      Eigen::Vector2d proj;
      Eigen::Matrix<double, 2, 6> J;
      if (!ProjectionJacobians(T, X[i], &proj, &J, nullptr)) continue;
      const Eigen::Vector2d r = proj - xy[i];
      const double e = r.norm();
      const double w = e <= huber ? 1.0 : huber / e;
      H += w * J.transpose() * J;
      g += w * J.transpose() * r;
      ++n;
    }
    if (n < 3) break;
    if (rotation_prior) {
      // r = Log(R target^T); under R' = Exp(w) R, dr/dw = J_l^-1(r).
      const Eigen::Vector3d r = LogSO3(T.RotationMatrix() * prior_target_t);
      const Eigen::Matrix3d Jr = LeftJacobianInverseSO3(r);
      H.block<3, 3>(3, 3) += prior_weight * Jr.transpose() * Jr;
      g.tail<3>() += prior_weight * Jr.transpose() * r;
    }
    const Vector6d delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) break;
    T = Rigid3d::Exp(delta) * T;
    if (delta.norm() < 1e-10) break;
  }
  if (information) *information = H;
  return T;
}

PoseEstimate EstimatePose(const std::vector<Eigen::Vector3d>& X, const std::vector<Eigen::Vector2d>& xy,
                          double focal, const std::optional<Rigid3d>& prior,
                          const PoseEstimatorOptions& o,
                          const std::optional<PoseRotationPrior>& rotation_prior) {
  const PoseRotationPrior* rp = rotation_prior ? &*rotation_prior : nullptr;
  PoseEstimate out;
  const size_t n = X.size();
  if (n < 6) return out;
  auto count_inliers = [&](const Rigid3d& T, double thresh_px, std::vector<uint8_t>* mask) {
    mask->assign(n, 0);
    int c = 0;
    for (size_t i = 0; i < n; ++i) {
      const double e = ReprojectionError(T, X[i], xy[i]) * focal;
      if (e <= thresh_px) {
        (*mask)[i] = 1;
        ++c;
      }
    }
    return c;
  };
  Rigid3d T;
  std::vector<uint8_t> mask;
  bool have = false;
  if (prior) {
    // Refine the prediction on all correspondences first (robust), then check it.
    std::vector<uint8_t> all(n, 1);
    const Rigid3d refined = RefinePose(*prior, X, xy, all, focal, o.huber_px, o.refine_iterations, nullptr, rp,
                                        o.sigma_px);
    const int c = count_inliers(refined, o.ransac_threshold_px, &mask);
    if (c >= o.prior_inlier_ratio * static_cast<double>(n)) {
      T = refined;
      have = true;
    }
  }
  if (!have) {
    std::vector<cv::Point3d> obj(n);
    std::vector<cv::Point2d> img(n);
    for (size_t i = 0; i < n; ++i) {
      obj[i] = cv::Point3d(X[i].x(), X[i].y(), X[i].z());
      img[i] = cv::Point2d(xy[i].x(), xy[i].y());
    }
    cv::Mat rvec, tvec;
    std::vector<int> inl;
    const bool ok = cv::solvePnPRansac(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec, false,
                                       o.ransac_iterations, o.ransac_threshold_px / focal, 0.99, inl,
                                       cv::SOLVEPNP_EPNP);
    out.used_ransac = true;
    if (!ok || inl.size() < 6) return out;
    cv::Mat Rm;
    cv::Rodrigues(rvec, Rm);
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    cv::cv2eigen(Rm, R);
    cv::cv2eigen(tvec, t);
    T = Rigid3d(R, t);
    count_inliers(T, o.ransac_threshold_px, &mask);
  }
  Matrix6d info;
  for (int round = 0; round < 2; ++round) {
    T = RefinePose(T, X, xy, mask, focal, o.huber_px, o.refine_iterations, &info, rp, o.sigma_px);
    count_inliers(T, o.inlier_px, &mask);
  }
  int inliers = 0;
  double sq = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    ++inliers;
    const double e = ReprojectionError(T, X[i], xy[i]) * focal;
    sq += e * e;
  }
  out.cam_from_world = T;
  out.inliers = mask;
  out.num_inliers = inliers;
  out.rms_px = inliers ? std::sqrt(sq / inliers) : 0.0;
  // Covariance: sigma^2 (J^T J)^-1 with J in normalised units.
  const double sigma = o.sigma_px / focal;
  Eigen::FullPivLU<Matrix6d> lu(info);
  out.covariance = lu.isInvertible() ? Matrix6d(sigma * sigma * lu.inverse()) : Matrix6d(Matrix6d::Identity());
  out.ok = inliers >= 6;
  return out;
}

}  // namespace mbslam
