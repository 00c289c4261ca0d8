#include "services/perception/objects/ground_plane.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <string>
#include <vector>

#include "services/perception/objects/random.h"

namespace mbslam {
namespace {

// A tilted ground (normal 3 deg off z), two facades, and uniform outliers.
std::vector<Eigen::Vector3d> Scene(const GroundPlane& ground, double outlier_share, uint64_t seed) {
  ParticleRng rng(seed);
  std::vector<Eigen::Vector3d> points;
  const Eigen::Vector3d u = ground.normal.unitOrthogonal();
  const Eigen::Vector3d v = ground.normal.cross(u);
  const Eigen::Vector3d origin = -ground.offset * ground.normal;
  for (int i = 0; i < 600; ++i) {
    points.push_back(origin + rng.Uniform(-20, 20) * u + rng.Uniform(-10, 10) * v +
                     rng.Normal(0.0, 0.01) * ground.normal);
  }
  for (int i = 0; i < 400; ++i) {  // facades y = +-8 (more points than any wrong plane)
    points.emplace_back(rng.Uniform(-20, 20), i % 2 ? 8.0 : -8.0, rng.Uniform(0, 8));
  }
  const int outliers = static_cast<int>(outlier_share * points.size() / (1.0 - outlier_share));
  for (int i = 0; i < outliers; ++i) {
    points.emplace_back(rng.Uniform(-20, 20), rng.Uniform(-8, 8), rng.Uniform(-2, 8));
  }
  return points;
}

TEST(GroundPlane, RansacFindsTiltedPlaneAmongFacadesAndOutliers) {
  GroundPlane truth;
  truth.normal =
      Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitX()) * Eigen::Vector3d::UnitZ();
  truth.offset = 1.5;  // the ground 1.5 units below the origin (a camera at the origin)
  const std::vector<Eigen::Vector3d> points = Scene(truth, 0.3, 7);
  GroundPlaneEstimate estimate;
  // A rough up hint (10 deg off).
  const Eigen::Vector3d up(0.0, 0.17, 1.0);
  ASSERT_TRUE(EstimateGroundPlane(points, up, &estimate).ok());
  EXPECT_LT(std::acos(std::min(1.0, estimate.plane.normal.dot(truth.normal))), 0.3 * M_PI / 180.0);
  EXPECT_NEAR(estimate.plane.offset, truth.offset, 0.01);
  EXPECT_GE(estimate.num_inliers, 590);
  EXPECT_LT(estimate.num_inliers, 700);
  EXPECT_LT(estimate.rms, 0.02);
  EXPECT_NEAR(estimate.inlier_ratio, estimate.num_inliers / static_cast<double>(points.size()),
              1e-12);
  // The camera (origin) is above the ground.
  EXPECT_NEAR(estimate.plane.Height(Eigen::Vector3d::Zero()), 1.5, 0.01);
}

TEST(GroundPlane, DeterministicForASeed) {
  GroundPlane truth;
  const std::vector<Eigen::Vector3d> points = Scene(truth, 0.5, 3);
  GroundPlaneEstimate a, b;
  ASSERT_TRUE(EstimateGroundPlane(points, Eigen::Vector3d::UnitZ(), &a).ok());
  ASSERT_TRUE(EstimateGroundPlane(points, Eigen::Vector3d::UnitZ(), &b).ok());
  EXPECT_EQ(a.plane.normal, b.plane.normal);
  EXPECT_EQ(a.plane.offset, b.plane.offset);
  EXPECT_EQ(a.num_inliers, b.num_inliers);
}

TEST(GroundPlane, RefusesBadInputAndScenesWithoutGround) {
  GroundPlaneEstimate estimate;
  EXPECT_FALSE(EstimateGroundPlane({}, Eigen::Vector3d::UnitZ(), &estimate).ok());
  EXPECT_FALSE(EstimateGroundPlane({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX()},
                                   Eigen::Vector3d::UnitZ(), &estimate)
                   .ok());
  std::vector<Eigen::Vector3d> walls;
  ParticleRng rng(1);
  for (int i = 0; i < 200; ++i) walls.emplace_back(rng.Uniform(-5, 5), 3.0, rng.Uniform(0, 3));
  EXPECT_FALSE(EstimateGroundPlane(walls, Eigen::Vector3d::Zero(), &estimate).ok());
  // Only a vertical wall: no plane within the tilt limit.
  EXPECT_FALSE(EstimateGroundPlane(walls, Eigen::Vector3d::UnitZ(), &estimate).ok());
  GroundPlaneOptions bad;
  bad.max_tilt_deg = 95.0;
  EXPECT_FALSE(bad.Check());
  EXPECT_FALSE(EstimateGroundPlane(walls, Eigen::Vector3d::UnitZ(), bad, &estimate).ok());
}

TEST(GroundPlane, Vector4RoundTripAndRescale) {
  const std::optional<GroundPlane> g = GroundPlane::FromVector4(Eigen::Vector4d(0, 0, 2, 3));
  ASSERT_TRUE(g);
  EXPECT_TRUE(g->IsValid());
  EXPECT_NEAR(g->normal.z(), 1.0, 1e-12);
  EXPECT_NEAR(g->offset, 1.5, 1e-12);
  EXPECT_TRUE(g->ToVector4().isApprox(Eigen::Vector4d(0, 0, 1, 1.5)));
  EXPECT_FALSE(GroundPlane::FromVector4(Eigen::Vector4d::Zero()));
  EXPECT_FALSE(GroundPlane::FromVector4(Eigen::Vector4d(0, 0, NAN, 1)));
  GroundPlane h = *g;
  h.Rescale(2.0);
  EXPECT_NEAR(h.Height(Eigen::Vector3d(0, 0, 1)), 4.0, 1e-12);  // offset 1.5 -> 3
}

// Ground points whose height error grows with the distance along x (a slightly wrong
// depth of far points): alone they fit a plane tilted about y. A camera that travelled
// along x at a constant height says the ground contains x: the constrained normal has no
// x component, and the camera's height above the plane no longer changes along its path.
TEST(GroundPlane, NormalPerpendicularToTheCamerasTravel) {
  ParticleRng rng(5);
  std::vector<Eigen::Vector3d> points;
  const double tilt = 2.0 * M_PI / 180.0;
  for (int i = 0; i < 800; ++i) {
    const double x = rng.Uniform(2, 30), y = rng.Uniform(-6, 6);
    points.emplace_back(x, y, -1.0 + std::tan(tilt) * x + rng.Normal(0.0, 0.005));
  }
  GroundPlaneOptions options;
  options.inlier_threshold = 0.05;
  GroundPlaneEstimate free_fit, along;
  ASSERT_TRUE(EstimateGroundPlane(points, Eigen::Vector3d::UnitZ(), options, &free_fit).ok());
  EXPECT_GT(std::abs(free_fit.plane.normal.x()), 0.5 * std::sin(tilt));  // tilted with the data
  EXPECT_GT(std::abs(free_fit.plane.Height(Eigen::Vector3d::Zero()) - free_fit.plane.Height(Eigen::Vector3d(9, 0, 0))), 0.1);
  // Keyframe centres along x at height 0 (z bobs a little): one travel direction.
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < 20; ++k) centres.emplace_back(0.5 * k, 0.01 * (k % 2), 0.0);
  const std::vector<Eigen::Vector3d> dirs = SpreadDirections(centres, Eigen::Vector3d::UnitZ(), 25.0, 1.0);
  ASSERT_EQ(dirs.size(), 1u);
  EXPECT_GT(std::abs(dirs[0].x()), 0.99);
  EXPECT_TRUE(SpreadDirections(centres, Eigen::Vector3d::UnitZ(), 25.0, 10.0).empty());  // too short
  ASSERT_TRUE(EstimateGroundPlane(points, Eigen::Vector3d::UnitZ(), options, dirs, &along).ok());
  EXPECT_LT(std::abs(along.plane.normal.x()), 1e-4);  // free fit: 0.035
  EXPECT_GT(along.plane.normal.z(), 0.99);
  EXPECT_NEAR(along.plane.Height(centres[0]), along.plane.Height(centres[18]), 1e-4);  // free fit: 0.3
  // A vertical spread (a camera moving up and down) is no ground direction.
  std::vector<Eigen::Vector3d> lift;
  for (int k = 0; k < 20; ++k) lift.emplace_back(0.0, 0.0, 0.5 * k);
  EXPECT_TRUE(SpreadDirections(lift, Eigen::Vector3d::UnitZ(), 25.0, 1.0).empty());
}

// A low camera (0.03 units) looking down a long street: the map's inlier band (0.05
// units) is wider than the camera's height, and a slope ahead holding more points than
// the ground wins the free fit, 20 deg off. The travel (0.1 units along x) is short
// against the camera's height above that plane (0.05) but long against its height above
// the plane fitted along it (0.03): that one, the ground, is taken.
TEST(GroundPlane, AlongTravelRejectsASlopeThatOutnumbersTheGround) {
  ParticleRng rng(7);
  std::vector<Eigen::Vector3d> points;
  const double h = 0.03, slope = 20.0 * M_PI / 180.0;
  for (int i = 0; i < 400; ++i) {
    points.emplace_back(rng.Uniform(0.1, 1.5), rng.Uniform(-0.3, 0.3), -h + rng.Normal(0.0, 0.01));
  }
  for (int i = 0; i < 500; ++i) {
    const double x = rng.Uniform(0.6, 1.5);
    points.emplace_back(x, rng.Uniform(-0.3, 0.3), -0.09 + std::tan(slope) * x + rng.Normal(0.0, 0.01));
  }
  GroundPlaneOptions options;
  options.inlier_threshold = 0.05;
  options.inlier_threshold_camera_heights = 0.0;  // the band in world units throughout (tested below)
  GroundPlaneEstimate free_fit;
  ASSERT_TRUE(EstimateGroundPlane(points, Eigen::Vector3d::UnitZ(), options, &free_fit).ok());
  EXPECT_GT(std::abs(free_fit.plane.normal.x()), std::sin(15.0 * M_PI / 180.0));  // the slope won
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < 12; ++k) centres.emplace_back(0.01 * k, 0.0, 0.0);  // spread 0.034
  const Eigen::Vector3d camera = centres.back();
  GroundPlaneEstimate estimate;
  bool along = false;
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), centres, camera, options, &estimate,
                                             &along).ok());
  EXPECT_TRUE(along);
  EXPECT_GT(estimate.plane.normal.z(), 0.999);
  EXPECT_NEAR(estimate.plane.Height(camera), h, 0.005);
  // Travel too short even against the ground's height, along x: the slope contradicts
  // it, so there is no plane. Along y (across the slope's tilt) the travel does not, but
  // the ground's points lie under the slope: no plane either ...
  std::vector<Eigen::Vector3d> short_travel, short_across;
  for (int k = 0; k < 12; ++k) {
    short_travel.emplace_back(0.002 * k, 0.0, 0.0);
    short_across.emplace_back(0.0, 0.002 * k, 0.0);
  }
  Status s = EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), short_travel, short_travel.back(),
                                            options, &estimate, &along);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("tilted"), std::string::npos) << s.message();
  s = EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), short_across, short_across.back(), options,
                                     &estimate, &along);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("below the plane"), std::string::npos) << s.message();
  s = EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate, &along);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("below the plane"), std::string::npos) << s.message();
  // ... unless points under the plane are allowed: then the free fit stays.
  options.max_below_share = 1.0;
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), short_across, short_across.back(),
                                             options, &estimate, &along).ok());
  EXPECT_FALSE(along);
  EXPECT_NEAR(estimate.plane.normal.x(), free_fit.plane.normal.x(), 1e-12);
  // No travel given (camera height unknown): the free fit.
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate,
                                             &along).ok());
  EXPECT_FALSE(along);
  // A camera below the plane: no ground.
  EXPECT_FALSE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, Eigen::Vector3d(0.1, 0.0, -0.5),
                                              options, &estimate, &along).ok());
  // Below min_support: an error, no plane.
  options.min_support = 0.9;
  EXPECT_FALSE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), centres, camera, options, &estimate,
                                              &along).ok());
}

// Nothing static lies under the ground: a plane with a share of the points below it
// beyond max_below_share is refused, whatever its support; the ground under a scene with
// a few points below it (noise, reflections) stays.
TEST(GroundPlane, AlongTravelRefusesAPlaneWithPointsBelowIt) {
  ParticleRng rng(3);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 500; ++i) points.emplace_back(rng.Uniform(-2, 2), rng.Uniform(1, 5), -1.0 + rng.Normal(0.0, 0.005));
  for (int i = 0; i < 300; ++i) points.emplace_back(rng.Uniform(-2, 2), rng.Uniform(1, 5), rng.Uniform(-0.9, 1.0));
  const int below = 50;  // 50 of 850: 5.9 %
  for (int i = 0; i < below; ++i) points.emplace_back(rng.Uniform(-2, 2), rng.Uniform(1, 5), rng.Uniform(-1.5, -1.1));
  GroundPlaneOptions options;
  options.inlier_threshold_camera_heights = 0.0;
  GroundPlaneEstimate estimate;
  bool along = false;
  const Eigen::Vector3d camera = Eigen::Vector3d::Zero();
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate,
                                             &along).ok());
  EXPECT_NEAR(estimate.plane.Height(camera), 1.0, 0.01);
  // 110 below of 910 (12.1 %): not the ground.
  for (int i = 0; i < below + 10; ++i) points.emplace_back(rng.Uniform(-2, 2), rng.Uniform(1, 5), rng.Uniform(-1.5, -1.1));
  const Status s = EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate, &along);
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("below the plane"), std::string::npos) << s.message();
  options.max_below_share = 0.13;
  EXPECT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate, &along).ok());
}

// An up-to-scale map whose unit is large against the camera's height (0.03 units above
// the ground, band 0.05 units): the ground's points (0.002 noise) and as many points of
// things standing on it (up to half the camera's height: kerbs, car bodies, walls' feet)
// all fall within the band, on one side, and the plane fitted to them rises above the
// ground. Refitted with the band narrowed to 0.15 camera heights, the plane is the ground
// (within 3 % of the camera's height; the wide band's is more than 10 % too high).
TEST(GroundPlane, BandInCameraHeightsKeepsThePlaneOnTheGround) {
  ParticleRng rng(11);
  std::vector<Eigen::Vector3d> points;
  const double h = 0.03;
  for (int i = 0; i < 400; ++i) {
    points.emplace_back(rng.Uniform(0.1, 1.5), rng.Uniform(-0.3, 0.3), -h + rng.Normal(0.0, 0.002));
  }
  for (int i = 0; i < 400; ++i) {
    points.emplace_back(rng.Uniform(0.1, 1.5), rng.Uniform(-0.3, 0.3), -h + rng.Uniform(0.0, 0.5 * h));
  }
  std::vector<Eigen::Vector3d> centres;
  for (int k = 0; k < 12; ++k) centres.emplace_back(0.01 * k, 0.0, 0.0);
  const Eigen::Vector3d camera = centres.back();
  GroundPlaneOptions options;
  options.inlier_threshold = 0.05;
  options.inlier_threshold_camera_heights = 0.0;  // world units only: the plane rises
  GroundPlaneEstimate estimate;
  bool along = false;
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate,
                                             &along).ok());
  EXPECT_LT(estimate.plane.Height(camera), 0.9 * h);
  options.inlier_threshold_camera_heights = 0.15;
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), {}, camera, options, &estimate,
                                             &along).ok());
  EXPECT_NEAR(estimate.plane.Height(camera), h, 0.03 * h);
  EXPECT_GT(estimate.plane.normal.z(), 0.999);
  ASSERT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), centres, camera, options, &estimate,
                                             &along).ok());
  EXPECT_NEAR(estimate.plane.Height(camera), h, 0.03 * h);
  // Support is still measured in the world-unit band: the narrowed fit holds only the
  // ground's half of the points, yet the plane is kept at min_support 0.6.
  options.min_support = 0.6;
  EXPECT_TRUE(EstimateGroundPlaneAlongTravel(points, Eigen::Vector3d::UnitZ(), centres, camera, options, &estimate,
                                             &along).ok());
}

}  // namespace
}  // namespace mbslam
