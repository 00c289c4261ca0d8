#include "services/perception/geometry/rigid3.h"

#include <gtest/gtest.h>

#include <random>

namespace mbslam {
namespace {

Vector6d RandomTwist(std::mt19937* rng, double scale) {
  std::normal_distribution<double> n(0.0, scale);
  Vector6d xi;
  for (int i = 0; i < 6; ++i) xi[i] = n(*rng);
  return xi;
}

TEST(Rigid3d, ExpLogRoundTrip) {
  std::mt19937 rng(1);
  for (int i = 0; i < 200; ++i) {
    Vector6d xi = RandomTwist(&rng, 0.8);
    if (xi.tail<3>().norm() > 3.0) continue;
    const Vector6d back = Rigid3d::Exp(xi).Log();
    EXPECT_LT((back - xi).norm(), 1e-9) << xi.transpose();
  }
  // Tiny and zero rotations.
  Vector6d small;
  small << 1.0, -2.0, 0.5, 1e-10, -2e-10, 0.0;
  EXPECT_LT((Rigid3d::Exp(small).Log() - small).norm(), 1e-12);
}

TEST(Rigid3d, ExpMatchesMatrixExponential) {
  std::mt19937 rng(2);
  const Vector6d xi = RandomTwist(&rng, 0.5);
  Eigen::Matrix4d X = Eigen::Matrix4d::Zero();
  X.topLeftCorner<3, 3>() = Hat(xi.tail<3>());
  X.topRightCorner<3, 1>() = xi.head<3>();
  // Series of the 4x4 matrix exponential.
  Eigen::Matrix4d sum = Eigen::Matrix4d::Identity(), term = Eigen::Matrix4d::Identity();
  for (int k = 1; k < 30; ++k) {
    term = term * X / k;
    sum += term;
  }
  EXPECT_LT((Rigid3d::Exp(xi).ToMatrix() - sum).norm(), 1e-10);
}

TEST(Rigid3d, InverseAndComposition) {
  std::mt19937 rng(3);
  const Rigid3d a = Rigid3d::Exp(RandomTwist(&rng, 1.0));
  const Rigid3d b = Rigid3d::Exp(RandomTwist(&rng, 1.0));
  const Eigen::Vector3d p(0.3, -1.0, 2.0);
  EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-12);
  EXPECT_LT(((a.Inverse() * a) * p - p).norm(), 1e-12);
  EXPECT_LT(((a * b).ToMatrix() - a.ToMatrix() * b.ToMatrix()).norm(), 1e-12);
}

TEST(Rigid3d, AdjointMovesTwistsBetweenFrames) {
  std::mt19937 rng(4);
  const Rigid3d T = Rigid3d::Exp(RandomTwist(&rng, 1.0));
  const Vector6d xi = RandomTwist(&rng, 0.3);
  const Rigid3d lhs = T * Rigid3d::Exp(xi);
  const Rigid3d rhs = Rigid3d::Exp(T.Adjoint() * xi) * T;
  EXPECT_LT((lhs.ToMatrix() - rhs.ToMatrix()).norm(), 1e-10);
}

TEST(Rigid3d, InterpolationEndpointsAndMidpoint) {
  std::mt19937 rng(5);
  const Rigid3d a = Rigid3d::Exp(RandomTwist(&rng, 1.0));
  const Vector6d xi = RandomTwist(&rng, 0.4);
  const Rigid3d b = a * Rigid3d::Exp(xi);
  EXPECT_LT((Rigid3d::Interpolate(a, b, 0.0).ToMatrix() - a.ToMatrix()).norm(), 1e-12);
  EXPECT_LT((Rigid3d::Interpolate(a, b, 1.0).ToMatrix() - b.ToMatrix()).norm(), 1e-10);
  const Rigid3d mid = a * Rigid3d::Exp(0.5 * xi);
  EXPECT_LT((Rigid3d::Interpolate(a, b, 0.5).ToMatrix() - mid.ToMatrix()).norm(), 1e-10);
}

TEST(Rigid3d, LeftJacobianInverse) {
  std::mt19937 rng(6);
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d w = RandomTwist(&rng, 0.7).head<3>();
    EXPECT_LT((LeftJacobianSO3(w) * LeftJacobianInverseSO3(w) - Eigen::Matrix3d::Identity()).norm(),
              1e-10);
  }
}

TEST(Sim3d, InverseAndPoseApplication) {
  Sim3d s;
  s.scale = 2.5;
  s.rotation = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized());
  s.translation = Eigen::Vector3d(1, -2, 0.5);
  const Eigen::Vector3d p(0.2, 0.4, -1.0);
  EXPECT_LT((s.Inverse() * (s * p) - p).norm(), 1e-12);
  const Rigid3d pose(Eigen::Quaterniond::Identity(), p);
  EXPECT_LT(((s * pose).translation - s * p).norm(), 1e-12);
}

}  // namespace
}  // namespace mbslam
