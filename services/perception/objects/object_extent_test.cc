#include "services/perception/objects/object_extent.h"

#include <gtest/gtest.h>

#include <vector>

#include "services/perception/objects/random.h"

namespace mbslam {
namespace {

// World z up; the camera 1.5 up at the origin looking along world x.
Rigid3d CamFromWorld() {
  Eigen::Matrix3d world_from_cam;
  world_from_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Rigid3d(world_from_cam, Eigen::Vector3d(0, 0, 1.5)).Inverse();
}

// Tracks spread uniformly over a 1.8 wide, 1.5 high face 10 units ahead, on the ground.
std::vector<Eigen::Vector2d> FaceTracks(const Rigid3d& cam_from_world, int n, uint64_t seed) {
  ParticleRng rng(seed);
  std::vector<Eigen::Vector2d> xy;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector3d p(10.0, rng.Uniform(-0.9, 0.9), rng.Uniform(0.0, 1.5));
    xy.push_back((cam_from_world * p).hnormalized());
  }
  return xy;
}

TEST(ObjectExtent, WidthAndHeightFromTracksAtTheDepth) {
  const Rigid3d cam_from_world = CamFromWorld();
  const std::vector<Eigen::Vector2d> tracks = FaceTracks(cam_from_world, 200, 3);
  const Eigen::Vector2d ref = (cam_from_world * Eigen::Vector3d(10.0, 0.0, 0.75)).hnormalized();
  ObjectExtentOptions options;
  options.depth_to_width_ratio = 2.0;
  ObjectExtentEstimator estimator(options);
  ASSERT_TRUE(estimator.Update(cam_from_world, tracks, ref, 10.0, Eigen::Vector3d::UnitZ()).ok());
  const ObjectExtent& e = estimator.extent();
  ASSERT_TRUE(e.valid);
  EXPECT_NEAR(e.size.y(), 1.8, 0.15);               // width
  EXPECT_NEAR(e.size.z(), 1.5, 0.12);               // height
  EXPECT_NEAR(e.size.x(), 2.0 * e.size.y(), 1e-9);  // unseen depth from the ratio
  // Box axes: x along the view (world x), z up.
  const Eigen::Matrix3d R = e.world_from_box.toRotationMatrix();
  EXPECT_GT(R.col(0).dot(Eigen::Vector3d::UnitX()), 0.999);
  EXPECT_GT(R.col(2).dot(Eigen::Vector3d::UnitZ()), 0.999);
  // The box centre is half its depth behind the face, level with the face's middle.
  const Eigen::Vector3d center = Eigen::Vector3d(10.0, 0.0, 0.75) + e.center_offset;
  EXPECT_NEAR(center.x(), 10.0 + 0.5 * e.size.x(), 0.05);
  EXPECT_NEAR(center.y(), 0.0, 0.1);
  EXPECT_NEAR(center.z(), 0.75, 0.1);
  // Sizes along the world axes: the same box; along axes turned 90 deg about z, x and y swap.
  EXPECT_TRUE(e.SizeAlong(Eigen::Quaterniond::Identity()).isApprox(e.size, 1e-6));
  const Eigen::Quaterniond turned(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  const Eigen::Vector3d s = e.SizeAlong(turned);
  EXPECT_NEAR(s.x(), e.size.y(), 1e-6);
  EXPECT_NEAR(s.y(), e.size.x(), 1e-6);
}

TEST(ObjectExtent, SmoothsAndRescales) {
  const Rigid3d cam_from_world = CamFromWorld();
  const Eigen::Vector2d ref = (cam_from_world * Eigen::Vector3d(10.0, 0.0, 0.75)).hnormalized();
  ObjectExtentEstimator estimator;
  ASSERT_TRUE(estimator
                  .Update(cam_from_world, FaceTracks(cam_from_world, 100, 1), ref, 10.0,
                          Eigen::Vector3d::UnitZ())
                  .ok());
  const double first = estimator.extent().size.z();
  // The same tracks placed twice as deep: the new image counts with the smoothing gain.
  ASSERT_TRUE(estimator
                  .Update(cam_from_world, FaceTracks(cam_from_world, 100, 1), ref, 20.0,
                          Eigen::Vector3d::UnitZ())
                  .ok());
  EXPECT_NEAR(estimator.extent().size.z(), first * (1.0 + ObjectExtentOptions().smoothing), 1e-6);
  estimator.RescaleWorld(0.5);
  EXPECT_NEAR(estimator.extent().size.z(), 0.5 * first * (1.0 + ObjectExtentOptions().smoothing),
              1e-6);
  EXPECT_EQ(estimator.num_updates(), 2);
}

TEST(ObjectExtent, RefusesTooFewTracksAndBadInput) {
  const Rigid3d cam_from_world = CamFromWorld();
  ObjectExtentEstimator estimator;
  const Eigen::Vector2d ref(0.0, 0.0);
  EXPECT_FALSE(
      estimator
          .Update(cam_from_world, {{0.0, 0.0}, {0.1, 0.1}}, ref, 10.0, Eigen::Vector3d::UnitZ())
          .ok());
  EXPECT_FALSE(estimator
                   .Update(cam_from_world, FaceTracks(cam_from_world, 10, 2), ref, -1.0,
                           Eigen::Vector3d::UnitZ())
                   .ok());
  EXPECT_FALSE(estimator
                   .Update(cam_from_world, FaceTracks(cam_from_world, 10, 2), ref, 10.0,
                           Eigen::Vector3d::Zero())
                   .ok());
  EXPECT_FALSE(estimator.extent().valid);
  EXPECT_TRUE(estimator.extent().HalfSizeAlong(Eigen::Matrix3d::Identity()).isZero());
}

}  // namespace
}  // namespace mbslam
