// A map lost and re-initialised continues the lost map's world frame and units
// (SlamOptions::bridge_units). Monocular, the new map's scale is unobservable across the
// gap: "speed" assumes the camera kept its velocity, "depth" that the scene kept its
// depth. Here the camera approaches the scene before the loss (the map's depths shrink,
// so the right new units are not those of a fresh map, median depth 1) and slides
// sideways 2.5x faster after it.

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

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
struct Scene {
  std::vector<Eigen::Vector3d> points;
  explicit Scene(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> ux(-4.0, 14.0), uy(-0.4, 0.4), u01(0.0, 1.0);
    for (int i = 0; i < 3000; ++i) {
      const double z = 6.0 + 10.0 * u01(rng) * u01(rng);
      points.emplace_back(ux(rng), uy(rng) * z, z);
    }
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

// The ratio of the new map's units to the lost map's (1 = continued exactly).
double UnitRatioAfterLoss(const std::string& units) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.lost_frames_to_reinit = 3;
  options.bridge_units = units;
  SlamSystem slam(options);
  std::map<int, Eigen::Vector3d> centres;
  for (int f = 0; f < kEnd; ++f) {
    const SlamFrame frame = scene.Frame(f);
    const SlamPose pose = slam.TrackPose(frame);
    if (pose.valid) centres[f] = pose.cam_from_world.Inverse().translation;
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
}

}  // namespace
}  // namespace mbslam
