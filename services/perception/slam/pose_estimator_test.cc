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

// A small object far ahead: a turn about the vertical and a sideways translation explain
// its few degrees of view almost alike. Started from a pose turned by 0.1 rad and moved
// sideways to compensate, the refinement alone leaves much of the turn; the rotation
// prior (the true rotation, 0.5 deg) brings it back, and the covariance of the rotation
// stays within the prior's.
TEST(PoseEstimator, RotationPriorResolvesTheNarrowViewAmbiguity) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.25, 0.25), z(-0.2, 0.2);
  std::normal_distribution<double> noise(0.0, 0.5 / 500.0);
  const Rigid3d truth(Eigen::Matrix3d(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())), Eigen::Vector3d(0.1, 0.0, 8.0));
  std::vector<Eigen::Vector3d> X;
  std::vector<Eigen::Vector2d> xy;
  for (int i = 0; i < 40; ++i) {
    const Eigen::Vector3d p(u(rng), 4.0 * u(rng), z(rng));  // object frame, a person-sized box
    X.push_back(p);
    xy.push_back((truth * p).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  // Turned by 0.1 rad about the vertical; the object's centre (its origin) still projects
  // where it did.
  const Rigid3d start(Eigen::Matrix3d(Eigen::AngleAxisd(0.15, Eigen::Vector3d::UnitY())), truth.translation);
  const std::vector<uint8_t> all(X.size(), 1);
  const Rigid3d free = RefinePose(start, X, xy, all, 500.0, 1.5, 10, nullptr);
  PoseRotationPrior prior;
  prior.cam_from_world = truth.rotation;
  prior.sigma_rad = 0.5 * M_PI / 180.0;
  Matrix6d info;
  const Rigid3d held = RefinePose(start, X, xy, all, 500.0, 1.5, 10, &info, &prior, 1.0);
  EXPECT_GT(RotationDistance(free, truth), 0.02);
  EXPECT_LT(RotationDistance(held, truth), 0.005);
  EXPECT_LT(RotationDistance(held, truth), 0.25 * RotationDistance(free, truth));
  // Covariance: sigma^2 (info)^-1 in normalised units; its rotation block within the prior's.
  const double s = 1.0 / 500.0;
  const Matrix6d cov = s * s * Matrix6d(info.inverse());
  EXPECT_LE(cov(4, 4), prior.sigma_rad * prior.sigma_rad * 1.0001);
  // Through EstimatePose too.
  const PoseEstimate est = EstimatePose(X, xy, 500.0, start, PoseEstimatorOptions(), prior);
  ASSERT_TRUE(est.ok);
  EXPECT_LT(RotationDistance(est.cam_from_world, truth), 0.005);
}

}  // namespace
}  // namespace mbslam
