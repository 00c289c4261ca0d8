#include "tools/planner_example/path_checker.h"

#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace mbslam {
namespace planner {
namespace {

constexpr int64_t kNow = 1600000000000000;

// A wall of occupied voxels x in [2.0, 2.1], y in [-1, 1], z in [0, 1] (10 cm voxels),
// with the free space in front of it observed.
std::shared_ptr<const octomap::OcTree> Wall() {
  auto tree = std::make_shared<octomap::OcTree>(0.1);
  for (int j = -10; j < 10; ++j) {
    for (int k = 0; k < 10; ++k) {
      const double y = 0.1 * j + 0.05, z = 0.1 * k + 0.05;
      for (int i = 0; i < 20; ++i) {
        tree->updateNode(0.1 * i + 0.05, y, z, false);
      }
      tree->updateNode(2.05, y, z, true);
    }
  }
  return tree;
}

std::vector<Waypoint> Line(const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                           double duration_s) {
  Waypoint a, b;
  a.position = from;
  b.t_s = duration_s;
  b.position = to;
  return {a, b};
}

// A 1 m cube crossing x = 3 along y, at y = -2 now, y = 0 at +0.5 s, y = 2 at +1 s.
MovingObstacle Crossing(int id, double probability = 0.9) {
  MovingObstacle o;
  o.id = id;
  for (int h = 0; h <= 2; ++h) {
    OrientedBox box;
    box.utime = kNow + int64_t{500000} * h;
    box.center = Eigen::Vector3d(3.0, -2.0 + 2.0 * h, 0.5);
    box.half_extent = Eigen::Vector3d::Constant(0.5);
    box.probability = probability;
    o.volumes.push_back(box);
  }
  return o;
}

TEST(ParsePath, Formats) {
  std::vector<Waypoint> path;
  ASSERT_TRUE(
      ParsePath("# t x y z\n0 0 0 0\n0.5 1 0 0  # half way\n\n1.0, 2, 0.5, 0\n", &path).ok());
  ASSERT_EQ(path.size(), 3u);
  EXPECT_DOUBLE_EQ(path[1].t_s, 0.5);
  EXPECT_TRUE(path[2].position.isApprox(Eigen::Vector3d(2, 0.5, 0)));
  ASSERT_TRUE(ParsePath("0,0,0,0; 1,1,0,0", &path).ok());
  ASSERT_EQ(path.size(), 2u);
  EXPECT_FALSE(ParsePath("", &path).ok());
  EXPECT_FALSE(ParsePath("0 0 0", &path).ok());
  EXPECT_FALSE(ParsePath("0 0 0 x", &path).ok());
  EXPECT_FALSE(ParsePath("0 0 0 nan", &path).ok());
  EXPECT_FALSE(ParsePath("1 0 0 0; 0.5 1 0 0", &path).ok());
}

TEST(Volumes, InterpolationAndDistance) {
  MovingObstacle o = Crossing(1);
  o.volumes[2].orientation =
      Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  o.volumes[2].half_extent = Eigen::Vector3d(1.5, 0.5, 0.5);
  OrientedBox box;
  bool extrapolated = true;
  ASSERT_TRUE(VolumeAt(o, kNow + 250000, &box, &extrapolated));
  EXPECT_FALSE(extrapolated);
  EXPECT_TRUE(box.center.isApprox(Eigen::Vector3d(3, -1, 0.5)));
  ASSERT_TRUE(VolumeAt(o, kNow + 750000, &box));
  EXPECT_TRUE(box.center.isApprox(Eigen::Vector3d(3, 1, 0.5)));
  EXPECT_NEAR(box.half_extent.x(), 1.0, 1e-12);
  EXPECT_NEAR(box.orientation.angularDistance(
                  Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()))),
              0.0, 1e-9);
  ASSERT_TRUE(VolumeAt(o, kNow - 100000, &box, &extrapolated));  // before: the current box
  EXPECT_TRUE(box.center.isApprox(Eigen::Vector3d(3, -2, 0.5)));
  EXPECT_FALSE(extrapolated);
  ASSERT_TRUE(VolumeAt(o, kNow + 2000000, &box, &extrapolated));  // after: the last one
  EXPECT_TRUE(extrapolated);
  EXPECT_FALSE(VolumeAt(MovingObstacle(), kNow, &box));

  OrientedBox b;
  b.center = Eigen::Vector3d(1, 0, 0);
  b.half_extent = Eigen::Vector3d(2, 0.5, 0.5);
  b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  EXPECT_DOUBLE_EQ(DistanceToBox(b, Eigen::Vector3d(1, 1.9, 0)), 0.0);  // long axis along y
  EXPECT_NEAR(DistanceToBox(b, Eigen::Vector3d(2, 0, 0)), 0.5, 1e-12);
  EXPECT_NEAR(DistanceToBox(b, Eigen::Vector3d(1, 3, 0)), 1.0, 1e-12);
}

TEST(PathChecker, StaticWall) {
  PathChecker checker{PathCheckOptions()};
  checker.SetOccupancy(Wall());
  PathConflict c;
  PathCheckSummary s;
  // Straight through the wall at 4 m/s: the sphere (0.3 m) touches it at x = 1.7, t = 0.425 s.
  ASSERT_TRUE(checker.Check(Line({0.05, 0.05, 0.55}, {4.05, 0.05, 0.55}, 1.0), kNow, &c, &s).ok());
  ASSERT_EQ(c.kind, PathConflict::Kind::kOccupiedVoxel);
  EXPECT_NEAR(c.t_s, 0.4125, 0.02);
  EXPECT_NEAR(c.obstacle.x(), 2.05, 1e-6);
  EXPECT_EQ(c.segment, 0);
  EXPECT_EQ(c.Describe().rfind("blocked by occupied voxel at (2.05, 0.05, 0.55)", 0), 0u)
      << c.Describe();
  EXPECT_GT(s.voxels_tested, 0);
  // Beside the wall: free; passing its end closer than the radius: blocked.
  ASSERT_TRUE(checker.Check(Line({0.05, 3.0, 0.55}, {4.05, 3.0, 0.55}, 1.0), kNow, &c, &s).ok());
  EXPECT_FALSE(c.blocked());
  EXPECT_EQ(c.Describe(), "free");
  EXPECT_NEAR(s.checked_until_s, 1.0, 1e-9);
  ASSERT_TRUE(checker.Check(Line({0.05, 1.2, 0.55}, {4.05, 1.2, 0.55}, 1.0), kNow, &c).ok());
  EXPECT_TRUE(c.blocked());
  PathCheckOptions thin;
  thin.robot_radius = 0.1;
  PathChecker thin_checker(thin);
  thin_checker.SetOccupancy(Wall());
  ASSERT_TRUE(thin_checker.Check(Line({0.05, 1.2, 0.55}, {4.05, 1.2, 0.55}, 1.0), kNow, &c).ok());
  EXPECT_FALSE(c.blocked()) << c.Describe();
}

TEST(PathChecker, OnlyTheHorizonCounts) {
  PathChecker checker{PathCheckOptions()};
  checker.SetOccupancy(Wall());
  PathConflict c;
  // Reaches the wall after about 1.7 s.
  ASSERT_TRUE(checker.Check(Line({0.05, 0.05, 0.55}, {4.05, 0.05, 0.55}, 4.0), kNow, &c).ok());
  EXPECT_FALSE(c.blocked());
  PathCheckOptions longer;
  longer.horizon_s = 2.0;
  PathChecker checker2(longer);
  checker2.SetOccupancy(Wall());
  ASSERT_TRUE(checker2.Check(Line({0.05, 0.05, 0.55}, {4.05, 0.05, 0.55}, 4.0), kNow, &c).ok());
  EXPECT_TRUE(c.blocked());
  // A path that started in the past is checked from now on.
  std::vector<Waypoint> path = Line({-4.0, 0.05, 0.55}, {4.05, 0.05, 0.55}, 1.0);
  path[0].t_s = -1.0;  // at x = 0.025 now, at the wall after about 0.42 s
  ASSERT_TRUE(checker.Check(path, kNow, &c).ok());
  EXPECT_TRUE(c.blocked());
  EXPECT_GE(c.t_s, 0.0);
}

TEST(PathChecker, UnknownSpace) {
  PathCheckOptions options;
  options.unknown_is_occupied = true;
  PathChecker checker(options);
  checker.SetOccupancy(Wall());
  PathConflict c;
  // In the observed free space in front of the wall: free.
  ASSERT_TRUE(checker.Check(Line({0.5, 0.05, 0.55}, {1.5, 0.05, 0.55}, 1.0), kNow, &c).ok());
  EXPECT_FALSE(c.blocked()) << c.Describe();
  // Behind the wall nothing was seen.
  ASSERT_TRUE(checker.Check(Line({3.0, 0.05, 0.55}, {4.0, 0.05, 0.55}, 1.0), kNow, &c).ok());
  EXPECT_EQ(c.kind, PathConflict::Kind::kUnknownVoxel);
  EXPECT_EQ(c.Describe().rfind("blocked by unknown voxel", 0), 0u);
}

TEST(PathChecker, MovingObject) {
  PathChecker checker{PathCheckOptions()};
  checker.SetObstacles({Crossing(7)});
  PathConflict c;
  // Along x at 6 m/s... x = 3 at t = 0.5 s, when the box is there.
  ASSERT_TRUE(checker.Check(Line({0.0, 0.0, 0.5}, {6.0, 0.0, 0.5}, 1.0), kNow, &c).ok());
  ASSERT_EQ(c.kind, PathConflict::Kind::kObject);
  EXPECT_EQ(c.object_id, 7);
  EXPECT_NEAR(c.t_s, 0.4, 0.05);  // the sphere meets the box a little before
  EXPECT_NEAR(c.probability, 0.9, 1e-12);
  EXPECT_EQ(c.Describe().rfind("blocked by object 7", 0), 0u) << c.Describe();
  // Fast enough to be past before it comes: free, unless the robot then waits in its way.
  std::vector<Waypoint> fast = Line({0.0, 0.0, 0.5}, {6.0, 0.0, 0.5}, 0.2);
  ASSERT_TRUE(checker.Check(fast, kNow, &c).ok());
  EXPECT_FALSE(c.blocked()) << c.Describe();
  std::vector<Waypoint> stop = Line({0.0, 0.0, 0.5}, {3.0, 0.0, 0.5}, 0.1);
  ASSERT_TRUE(checker.Check(stop, kNow, &c).ok());
  EXPECT_TRUE(c.blocked());
  EXPECT_EQ(c.segment, 1);  // at rest at the last waypoint
  PathCheckOptions no_hold;
  no_hold.hold_last_waypoint = false;
  PathChecker checker2(no_hold);
  checker2.SetObstacles({Crossing(7)});
  ASSERT_TRUE(checker2.Check(stop, kNow, &c).ok());
  EXPECT_FALSE(c.blocked());
  // Volumes below the probability threshold are ignored.
  PathCheckOptions confident;
  confident.min_volume_probability = 0.95;
  PathChecker checker3(confident);
  checker3.SetObstacles({Crossing(7)});
  ASSERT_TRUE(checker3.Check(Line({0.0, 0.0, 0.5}, {6.0, 0.0, 0.5}, 1.0), kNow, &c).ok());
  EXPECT_FALSE(c.blocked());
}

TEST(PathChecker, FirstConflictInTime) {
  // The object is met at about 0.4 s, the wall (moved to x = 4.5) later: the object wins.
  auto tree = std::make_shared<octomap::OcTree>(0.1);
  for (int j = -10; j < 10; ++j) {
    tree->updateNode(4.55, 0.1 * j + 0.05, 0.55, true);
  }
  PathChecker checker{PathCheckOptions()};
  checker.SetOccupancy(tree);
  checker.SetObstacles({Crossing(2)});
  PathConflict c;
  ASSERT_TRUE(checker.Check(Line({0.0, 0.05, 0.55}, {6.0, 0.05, 0.55}, 1.0), kNow, &c).ok());
  EXPECT_EQ(c.kind, PathConflict::Kind::kObject);
  // Without the object, the wall.
  checker.SetObstacles({});
  ASSERT_TRUE(checker.Check(Line({0.0, 0.05, 0.55}, {6.0, 0.05, 0.55}, 1.0), kNow, &c).ok());
  EXPECT_EQ(c.kind, PathConflict::Kind::kOccupiedVoxel);
}

TEST(PathChecker, BadInput) {
  PathChecker checker{PathCheckOptions()};
  PathConflict c;
  EXPECT_FALSE(checker.Check({}, kNow, &c).ok());
  std::vector<Waypoint> path = Line({0, 0, 0}, {1, 0, 0}, 1.0);
  path[1].position.x() = NAN;
  EXPECT_FALSE(checker.Check(path, kNow, &c).ok());
  path = Line({0, 0, 0}, {1, 0, 0}, 1.0);
  path[1].t_s = -1.0;
  EXPECT_FALSE(checker.Check(path, kNow, &c).ok());
  // A single waypoint: the robot standing there.
  checker.SetOccupancy(Wall());
  Waypoint w;
  w.position = Eigen::Vector3d(2.0, 0.0, 0.5);
  ASSERT_TRUE(checker.Check({w}, kNow, &c).ok());
  EXPECT_TRUE(c.blocked());
  PathCheckOptions bad;
  bad.horizon_s = 0.0;
  EXPECT_FALSE(PathChecker(bad).Check(Line({0, 0, 0}, {1, 0, 0}, 1.0), kNow, &c).ok());
}

}  // namespace
}  // namespace planner
}  // namespace mbslam
