#include "services/perception/slam/triangulation.h"

#include <gtest/gtest.h>

#include <random>

namespace mbslam {
namespace {

TEST(Triangulation, DltRecoversPoint) {
  const Rigid3d a;
  const Rigid3d b(Eigen::Matrix3d(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())), Eigen::Vector3d(-0.5, 0.1, 0.0));
  const Eigen::Vector3d X(0.3, -0.2, 4.0);
  const auto Y = TriangulateDlt(a, (a * X).hnormalized(), b, (b * X).hnormalized());
  ASSERT_TRUE(Y);
  EXPECT_LT((*Y - X).norm(), 1e-9);
  EXPECT_GT(ParallaxAngle(a, b, X), 0.1);
  EXPECT_LT(ReprojectionError(b, X, (b * X).hnormalized()), 1e-12);
}

// The analytic projection Jacobians against central differences.
TEST(Triangulation, ProjectionJacobiansMatchNumeric) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 0.3);
  for (int trial = 0; trial < 20; ++trial) {
    Vector6d xi;
    for (int i = 0; i < 6; ++i) xi[i] = g(rng);
    const Rigid3d T = Rigid3d::Exp(xi);
    const Eigen::Vector3d X = T.Inverse() * Eigen::Vector3d(g(rng), g(rng), 3.0 + g(rng));
    Eigen::Vector2d x;
    Eigen::Matrix<double, 2, 6> Jp;
    Eigen::Matrix<double, 2, 3> Jx;
    ASSERT_TRUE(ProjectionJacobians(T, X, &x, &Jp, &Jx));
    const double h = 1e-6;
    for (int k = 0; k < 6; ++k) {
      Vector6d d = Vector6d::Zero();
      d[k] = h;
      const Eigen::Vector2d plus = (Rigid3d::Exp(d) * T * X).hnormalized();
      const Eigen::Vector2d minus = (Rigid3d::Exp(-d) * T * X).hnormalized();
      EXPECT_LT(((plus - minus) / (2 * h) - Jp.col(k)).norm(), 1e-6) << "pose column " << k;
    }
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d[k] = h;
      const Eigen::Vector2d plus = (T * (X + d)).hnormalized();
      const Eigen::Vector2d minus = (T * (X - d)).hnormalized();
      EXPECT_LT(((plus - minus) / (2 * h) - Jx.col(k)).norm(), 1e-6) << "point column " << k;
    }
  }
}

}  // namespace
}  // namespace mbslam
