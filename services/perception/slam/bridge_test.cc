// A map lost and re-initialised continues the lost map's world frame and units
// (SlamOptions::bridge_units). Monocular, the new map's scale is unobservable across the
// gap: "speed" assumes the camera kept its velocity, "depth" that the scene kept its
// depth. Here the camera approaches the scene before the loss (the map's depths shrink,
// so the right new units are not those of a fresh map, median depth 1) and slides
// sideways 2.5x faster after it.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <optional>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include "services/perception/slam/object_reconstruction.h"
#include "services/perception/slam/slam_system.h"

namespace mbslam {
namespace {

constexpr double kFocal = 500.0;
constexpr int kLostFrom = 30;   // no observations from here ...
constexpr int kLostUntil = 36;  // ... to here (exclusive): the map is lost
constexpr int kEnd = 80;

// The camera moves towards a band of points 6-16 m deep (skewed towards the near end),
// 8 cm per image, until the loss, then slides along x 20 cm per image; the tracks after
// the loss are new (nothing links the maps).
// With `ground`, a ground 1.5 m below the camera (y points down) holds 1500 more points
// (track ids from kGroundTrack on) and nothing of the band lies under it.
constexpr int kGroundTrack = 3000;
constexpr double kGroundY = 1.5;
struct Scene {
  std::vector<Eigen::Vector3d> points;
  explicit Scene(unsigned seed, bool ground = false) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> ux(-4.0, 14.0), uy(-0.4, 0.4), u01(0.0, 1.0);
    while (points.size() < kGroundTrack) {
      const double z = 6.0 + 10.0 * u01(rng) * u01(rng);
      const Eigen::Vector3d p(ux(rng), uy(rng) * z, z);
      if (!ground || p.y() < kGroundY - 0.1) points.push_back(p);
    }
    for (int i = 0; ground && i < 1500; ++i)
      points.emplace_back(-4.0 + 24.0 * u01(rng), kGroundY, 3.5 + 12.5 * u01(rng));
  }
  static Eigen::Vector3d Center(int f) {
    return f < kLostFrom ? Eigen::Vector3d(0.0, 0.0, 0.08 * f)
                         : Eigen::Vector3d(0.20 * (f - kLostFrom), 0.0, 0.08 * kLostFrom);
  }
  SlamFrame Frame(int f) const {
    SlamFrame frame;
    frame.frame_index = f;
    frame.utime = f * 100000;
    frame.focal_px = kFocal;
    if (f >= kLostFrom && f < kLostUntil) return frame;
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = points[i] - Center(f);
      if (p.z() < 0.5) continue;
      const Eigen::Vector2d xy = p.hnormalized();
      if (std::abs(xy.x()) > 0.6 || std::abs(xy.y()) > 0.45) continue;
      SlamObservation o;
      o.track_id = static_cast<int64_t>(i) + (f >= kLostUntil ? 100000 : 0);
      o.xy = xy;
      o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
      o.body_id = 0;
      o.p_static = 0.9;
      frame.observations.push_back(o);
    }
    return frame;
  }
};

// Estimated over true camera step, median over the live poses of [from, to).
double MedianStepRatio(const std::map<int, Eigen::Vector3d>& centres, int from, int to) {
  std::vector<double> r;
  for (int f = from; f + 1 < to; ++f) {
    auto a = centres.find(f), b = centres.find(f + 1);
    if (a == centres.end() || b == centres.end()) continue;
    r.push_back((b->second - a->second).norm() / (Scene::Center(f + 1) - Scene::Center(f)).norm());
  }
  if (r.empty()) return 0.0;
  std::nth_element(r.begin(), r.begin() + static_cast<long>(r.size() / 2), r.end());
  return r[r.size() / 2];
}

// The ground plane (unit normal towards the camera) fitted to the map's points of the
// ground's tracks, as PerceptionCore's fit would give it; nullopt with fewer than 30.
std::optional<Eigen::Vector4d> MapGround(const SlamSystem& slam, const Eigen::Vector3d& camera) {
  std::vector<Eigen::Vector3d> pts;
  for (int64_t t = kGroundTrack; t < kGroundTrack + 1500; ++t) {
    const int64_t pid = slam.map().PointOfTrack(t);
    if (pid >= 0) pts.push_back(slam.map().point(pid)->position);
  }
  if (pts.size() < 30) return std::nullopt;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : pts) cov += (p - c) * (p - c).transpose();
  Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvectors().col(0);
  if (n.dot(camera - c) < 0.0) n = -n;
  Eigen::Vector4d plane;
  plane << n, -n.dot(c);
  return plane;
}

// The ratio of the new map's units to the lost map's (1 = continued exactly). With
// `ground`, the scene has a ground and the SLAM is given the map's ground plane before
// the loss (slam.bridge_ground: the camera keeps its height above it).
double UnitRatioAfterLoss(const std::string& units, bool ground = false,
                          bool bridge_ground = true) {
  const Scene scene(5, ground);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.lost_frames_to_reinit = 3;
  options.bridge_units = units;
  options.bridge_ground = bridge_ground;
  SlamSystem slam(options);
  std::map<int, Eigen::Vector3d> centres;
  for (int f = 0; f < kEnd; ++f) {
    const SlamFrame frame = scene.Frame(f);
    const SlamPose pose = slam.TrackPose(frame);
    if (pose.valid) centres[f] = pose.cam_from_world.Inverse().translation;
    if (ground && pose.valid && f < kLostFrom) {
      if (const std::optional<Eigen::Vector4d> plane = MapGround(slam, centres[f]))
        slam.SetGroundPlane(*plane);
    }
    std::unordered_map<int64_t, int> labels;
    for (const SlamObservation& o : frame.observations) labels[o.track_id] = 0;
    slam.UpdateMap(frame, labels);
  }
  const double before = MedianStepRatio(centres, 10, kLostFrom);
  const double after = MedianStepRatio(centres, kLostUntil + 10, kEnd);
  EXPECT_GT(before, 0.0) << units;
  EXPECT_GT(after, 0.0) << units << ": no live poses after the loss";
  return before > 0.0 ? after / before : 0.0;
}

TEST(SlamBridge, DepthUnitsSurviveAChangeOfSpeed) {
  const double ratio = UnitRatioAfterLoss("depth");
  EXPECT_NEAR(ratio, 1.0, 0.15);
}

TEST(SlamBridge, SpeedUnitsAssumeTheOldVelocity) {
  // The camera is 2.5x faster after the gap; the old velocity makes the new map's units
  // that much larger (its baseline looks 2.5x shorter in them).
  const double ratio = UnitRatioAfterLoss("speed");
  EXPECT_NEAR(ratio, 0.4, 0.1);
}

// The speed bridge is 2.5x off here (the camera is faster after the gap) and the depth
// bridge within 15 %; with the ground both keep the camera's height above it, and the
// new map continues the old one's units.
TEST(SlamBridge, GroundUnitsKeepTheCamerasHeight) {
  EXPECT_NEAR(UnitRatioAfterLoss("speed", /*ground=*/true, /*bridge_ground=*/false), 0.4, 0.1);
  EXPECT_NEAR(UnitRatioAfterLoss("speed", /*ground=*/true), 1.0, 0.05);
  EXPECT_NEAR(UnitRatioAfterLoss("depth", /*ground=*/true), 1.0, 0.05);
}

TEST(SlamBridge, ObjectMapsKeepTheSpeedBridgeTheirOwnLossDelayAndNoAssistedPoses) {
  SlamOptions world;
  ObjectReconstructionOptions objects;
  objects.lost_frames_to_reinit = 7;
  const SlamOptions s = ObjectReconstruction::ObjectSlamOptions(objects, world);
  EXPECT_EQ(world.bridge_units, "depth");
  EXPECT_EQ(s.bridge_units, "speed");
  EXPECT_EQ(s.lost_frames_to_reinit, 7);
  EXPECT_TRUE(world.hybrid_tracking);
  EXPECT_FALSE(s.hybrid_tracking);
  // Nothing gives an object's map a ground plane.
  EXPECT_TRUE(world.hybrid_ground_length);
  EXPECT_TRUE(world.bridge_ground);
  EXPECT_FALSE(s.hybrid_ground_length);
  EXPECT_FALSE(s.bridge_ground);
}

// The ground under a camera tilted by 20 deg: 200 ground points 1.5 m below it (5 %
// noise), a table top at 0.8 m (100), a wall spanning every height (100) and 5 stray
// points under the ground. The ground's height is the lowest that holds enough points.
TEST(SlamBridge, CameraHeightAboveTheGround) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.01);
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(0.35, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d up = tilt * Eigen::Vector3d(0.0, -1.0, 0.0);  // camera y points down
  const auto at = [&](double height, double x, double z) -> Eigen::Vector3d {
    return tilt * Eigen::Vector3d(x, height, z);
  };
  std::vector<Eigen::Vector3d> wall, all;
  for (int i = 0; i < 100; ++i) wall.push_back(at(1.2 * u(rng) + 0.2, 3.0 * u(rng), 6.0));
  all = wall;
  for (int i = 0; i < 200; ++i)
    all.push_back(at(1.5 * (1.0 + 5.0 * noise(rng)), 3.0 * u(rng), 4.0 + 3.0 * u(rng)));
  for (int i = 0; i < 100; ++i)
    all.push_back(at(0.8 * (1.0 + noise(rng)), 0.5 * u(rng), 2.5 + 0.3 * u(rng)));
  for (int i = 0; i < 5; ++i) all.push_back(at(3.0 + 0.01 * i, u(rng), 5.0));
  const std::optional<double> h = CameraHeightAboveGround(all, up, 0.05, 15, 0.2);
  ASSERT_TRUE(h.has_value());
  EXPECT_NEAR(*h, 1.5, 0.015);
  // Without the ground the table top is taken: the height is that of the lowest surface
  // with enough points (a map that sees no floor gives a wrong height).
  std::vector<Eigen::Vector3d> no_ground = wall;
  for (size_t i = 300; i < all.size(); ++i) no_ground.push_back(all[i]);
  const std::optional<double> table = CameraHeightAboveGround(no_ground, up, 0.05, 15, 0.2);
  ASSERT_TRUE(table.has_value());
  EXPECT_NEAR(*table, 0.8, 0.01);
  // A wall alone has no height where enough points gather; nor have too few points.
  EXPECT_FALSE(CameraHeightAboveGround(wall, up, 0.05, 15, 0.2).has_value());
  EXPECT_FALSE(
      CameraHeightAboveGround(std::vector<Eigen::Vector3d>(all.begin() + 100, all.begin() + 110),
                              up, 0.05, 15, 0.2)
          .has_value());
}

}  // namespace
}  // namespace mbslam
