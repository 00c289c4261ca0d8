#include "tools/eval/point_metrics.h"

#include <gtest/gtest.h>

#include <random>

namespace mbslam {
namespace eval {
namespace {

// Points on the unit square z = 0, 1 cm apart.
std::vector<Eigen::Vector3d> Square() {
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i <= 100; ++i) {
    for (int j = 0; j <= 100; ++j) {
      pts.emplace_back(0.01 * i, 0.01 * j, 0.0);
    }
  }
  return pts;
}

TEST(NearestPoint, MatchesBruteForce) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 500; ++i) {
    pts.emplace_back(u(rng), u(rng), u(rng));
  }
  const NearestPoint nn(pts, 0.3);
  for (int q = 0; q < 200; ++q) {
    const Eigen::Vector3d x(u(rng), u(rng), u(rng));
    double brute = 10.0;
    for (const auto& p : pts) {
      brute = std::min(brute, (p - x).norm());
    }
    EXPECT_NEAR(nn.Distance(x, 10.0), brute, 1e-12);
  }
  EXPECT_DOUBLE_EQ(NearestPoint({}, 0.1).Distance(Eigen::Vector3d::Zero(), 3.0), 3.0);
}

TEST(CompareToSurface, KnownOffsetsAndCoverage) {
  const auto truth = Square();
  // A reconstruction of the left half of the square, 2 mm above it, plus 3 outliers.
  std::vector<Eigen::Vector3d> recon;
  for (const auto& p : truth) {
    if (p.x() <= 0.5) {
      recon.push_back(p + Eigen::Vector3d(0, 0, 0.002));
    }
  }
  const size_t inliers = recon.size();
  recon.emplace_back(5, 5, 5);
  recon.emplace_back(-5, 0, 0);
  recon.emplace_back(0.5, 0.5, 2.0);
  const ReconstructionError e = CompareToSurface(recon, truth, 0.005, 0.5);
  EXPECT_EQ(e.outliers, 3);
  EXPECT_EQ(e.accuracy.count, static_cast<int>(recon.size()));
  EXPECT_NEAR(e.accuracy.median, 0.002, 1e-12);
  EXPECT_NEAR(e.completeness, static_cast<double>(inliers) / truth.size(), 1e-12);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
