#include "services/perception/objects/predicted_volume.h"

#include <gtest/gtest.h>

#include <vector>

#include "services/perception/objects/random.h"

namespace mbslam {
namespace {

// A cloud stretched along a tilted direction (like particles along a viewing ray).
std::vector<Eigen::Vector3d> Cloud(int n, uint64_t seed, const Eigen::Vector3d& center) {
  ParticleRng rng(seed);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
                            Eigen::AngleAxisd(-0.1, Eigen::Vector3d::UnitY()).toRotationMatrix();
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < n; ++i) {
    points.push_back(
        center + R * Eigen::Vector3d(rng.Normal(0, 2.0), rng.Normal(0, 0.3), rng.Normal(0, 0.1)));
  }
  return points;
}

TEST(PredictedVolume, HoldsTheRequestedShareOfTheCloud) {
  const Eigen::Vector3d center(10, 2, 0.8);
  const std::vector<Eigen::Vector3d> cloud = Cloud(2000, 1, center);
  const PredictedVolume v = BoundingVolume(cloud, std::nullopt, ObjectExtent(), 0.9, 0.0);
  EXPECT_GE(v.probability, 0.9);
  EXPECT_LT(v.probability, 0.92);
  int inside = 0;
  for (const Eigen::Vector3d& p : cloud) inside += v.Contains(p) ? 1 : 0;
  EXPECT_NEAR(inside / 2000.0, v.probability, 1e-9);
  // Fresh samples from the same distribution: about 90 % inside.
  int fresh = 0;
  for (const Eigen::Vector3d& p : Cloud(4000, 2, center)) fresh += v.Contains(p) ? 1 : 0;
  EXPECT_NEAR(fresh / 4000.0, 0.9, 0.025);
  // The box's long axis follows the cloud.
  const Eigen::Vector3d long_axis =
      (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d::UnitX());
  EXPECT_GT(std::abs((v.orientation * Eigen::Vector3d::UnitX()).dot(long_axis)), 0.99);
  EXPECT_GT(v.half_extent.x(), 4.0 * v.half_extent.y());
  EXPECT_LT((v.center - center).norm(), 0.3);
}

TEST(PredictedVolume, UprightWithUpAndGrownByExtentAndMargin) {
  const std::vector<Eigen::Vector3d> cloud = Cloud(1000, 3, Eigen::Vector3d(5, 0, 1));
  const PredictedVolume bare =
      BoundingVolume(cloud, Eigen::Vector3d::UnitZ(), ObjectExtent(), 0.9, 0.0);
  EXPECT_GT((bare.orientation * Eigen::Vector3d::UnitZ()).z(), 1.0 - 1e-12);
  ObjectExtent extent;
  extent.valid = true;
  extent.world_from_box = bare.orientation;
  extent.size = Eigen::Vector3d(4.0, 2.0, 1.5);
  extent.center_offset = Eigen::Vector3d(0.1, 0.0, 0.0);
  const PredictedVolume grown = BoundingVolume(cloud, Eigen::Vector3d::UnitZ(), extent, 0.9, 0.25);
  EXPECT_TRUE(grown.half_extent.isApprox(
      bare.half_extent + 0.5 * extent.size + Eigen::Vector3d::Constant(0.25), 1e-9));
  EXPECT_TRUE(grown.center.isApprox(bare.center + extent.center_offset, 1e-12));
  EXPECT_DOUBLE_EQ(grown.probability, bare.probability);
}

TEST(PredictedVolume, EmptyAndPointClouds) {
  const PredictedVolume empty = BoundingVolume({}, std::nullopt, ObjectExtent(), 0.9, 0.0);
  EXPECT_EQ(empty.probability, 0.0);
  EXPECT_TRUE(empty.half_extent.isZero());
  const std::vector<Eigen::Vector3d> same(50, Eigen::Vector3d(1, 2, 3));
  const PredictedVolume point = BoundingVolume(same, std::nullopt, ObjectExtent(), 0.9, 0.1);
  EXPECT_TRUE(point.center.isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_DOUBLE_EQ(point.probability, 1.0);
  EXPECT_TRUE(point.Contains(Eigen::Vector3d(1.05, 2, 3)));
  EXPECT_FALSE(point.Contains(Eigen::Vector3d(1.2, 2, 3)));
  EXPECT_TRUE(PredictedVolumeOptions().Check());
  PredictedVolumeOptions bad;
  bad.step_us = 0;
  EXPECT_FALSE(bad.Check());
}

}  // namespace
}  // namespace mbslam
