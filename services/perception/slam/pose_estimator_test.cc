#include "services/perception/slam/pose_estimator.h"

#include <gtest/gtest.h>

#include <random>

namespace mbslam {
namespace {

TEST(PoseEstimator, EpnpRansacWithOutliersAndRefinement) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-2.0, 2.0), z(3.0, 10.0);
  std::normal_distribution<double> noise(0.0, 0.5 / 500.0);
  Vector6d xi;
  xi << 0.2, -0.1, 0.3, 0.05, -0.02, 0.1;
  const Rigid3d truth = Rigid3d::Exp(xi);
  std::vector<Eigen::Vector3d> X;
  std::vector<Eigen::Vector2d> xy;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d pc(u(rng), u(rng), z(rng));
    X.push_back(truth.Inverse() * pc);
    xy.push_back(pc.hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  for (int i = 0; i < 40; ++i) xy[static_cast<size_t>(i)] += Eigen::Vector2d(0.05, -0.03);  // outliers
  const PoseEstimate est = EstimatePose(X, xy, 500.0, std::nullopt, PoseEstimatorOptions());
  ASSERT_TRUE(est.ok);
  EXPECT_TRUE(est.used_ransac);
  EXPECT_LT(TranslationDistance(est.cam_from_world, truth), 0.02);
  EXPECT_LT(RotationDistance(est.cam_from_world, truth), 2e-3);
  EXPECT_GE(est.num_inliers, 155);
  EXPECT_LE(est.num_inliers, 160);
  EXPECT_LT(est.rms_px, 1.0);
  // The covariance is positive definite and small.
  EXPECT_GT(est.covariance.determinant(), 0.0);
  EXPECT_LT(est.covariance.trace(), 1e-3);
  // A good prior skips RANSAC.
  const PoseEstimate again = EstimatePose(X, xy, 500.0, truth, PoseEstimatorOptions());
  EXPECT_FALSE(again.used_ransac);
  EXPECT_LT(TranslationDistance(again.cam_from_world, truth), 0.02);
}

}  // namespace
}  // namespace mbslam
