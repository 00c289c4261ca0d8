#include "services/perception/objects/bearing_only_tracker.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace mbslam {
namespace {

// World z up; a camera 1.5 up looking along world x, moving forward at 1 unit/s.
Rigid3d CamFromWorld(double t) {
  Eigen::Matrix3d world_from_cam;
  world_from_cam << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return Rigid3d(world_from_cam, Eigen::Vector3d(t, 0.0, 1.5)).Inverse();
}

GroundPlane Ground() { return GroundPlane(); }  // z = 0, normal +z

// A bearing of `point` from the camera at time t (s), with the ground plane.
BotObservation Observe(const Eigen::Vector3d& point, double t) {
  BotObservation o;
  o.utime = static_cast<int64_t>(std::llround(t * 1e6));
  o.cam_from_world = CamFromWorld(t);
  o.focal_px = 500.0;
  o.xy = (o.cam_from_world * point).hnormalized();
  o.ground_plane = Ground();
  return o;
}

BearingOnlyTrackerOptions SmallOptions() {
  BearingOnlyTrackerOptions options;
  options.num_particles = 300;
  return options;
}

double Depth(const Rigid3d& cam_from_world, const Eigen::Vector3d& p) {
  return (cam_from_world * p).z();
}

TEST(BearingOnlyTracker, OptionsCheck) {
  EXPECT_TRUE(BearingOnlyTrackerOptions().Check());
  BearingOnlyTrackerOptions bad;
  bad.num_particles = 0;
  EXPECT_FALSE(bad.Check());
  bad = BearingOnlyTrackerOptions();
  bad.init_depth_max = bad.init_depth_min;
  EXPECT_FALSE(bad.Check());
  bad = BearingOnlyTrackerOptions();
  bad.volumes.probability = 0.0;
  EXPECT_FALSE(bad.Check());
  // Invalid options are reported by the calls, never a crash.
  BearingOnlyTracker tracker(bad, 1);
  EXPECT_FALSE(tracker.Initialize(Observe(Eigen::Vector3d(10, 0, 0.8), 0.0)).ok());
  EXPECT_FALSE(tracker.initialized());
}

TEST(BearingOnlyTracker, RefusesBadInputAndTimeGoingBackwards) {
  BearingOnlyTracker tracker(SmallOptions(), 1);
  const Eigen::Vector3d target(10, 0, 0.8);
  EXPECT_FALSE(tracker.Update(Observe(target, 0.0)).ok());  // before Initialize
  EXPECT_FALSE(tracker.Predict(0).ok());
  BotObservation nan = Observe(target, 0.0);
  nan.xy.x() = NAN;
  EXPECT_FALSE(tracker.Initialize(nan).ok());
  BotObservation no_focal = Observe(target, 0.0);
  no_focal.focal_px = 0.0;
  EXPECT_FALSE(tracker.Initialize(no_focal).ok());
  ASSERT_TRUE(tracker.Initialize(Observe(target, 1.0)).ok());
  EXPECT_FALSE(tracker.Update(Observe(target, 0.5)).ok());
  BotObservation empty_bound = Observe(target, 1.1);
  empty_bound.depth_bound = DepthRange{5.0, 4.0};
  EXPECT_FALSE(tracker.Update(empty_bound).ok());
  EXPECT_EQ(tracker.stats().rejected_inputs, 2);           // since the (re-)initialisation
  EXPECT_TRUE(tracker.Update(Observe(target, 1.0)).ok());  // same time: no motion
  EXPECT_EQ(tracker.utime(), 1000000);
}

TEST(BearingOnlyTracker, InitialisesAlongTheRayWithinTheDepthBound) {
  BearingOnlyTrackerOptions options = SmallOptions();
  options.cues.size_bound = false;
  BearingOnlyTracker tracker(options, 7);
  BotObservation o = Observe(Eigen::Vector3d(8, 1, 0.9), 0.0);
  o.depth_bound = DepthRange{4.0, 12.0};
  ASSERT_TRUE(tracker.Initialize(o).ok());
  ASSERT_EQ(tracker.particles().size(), 300u);
  double mean = 0.0;
  for (const BotParticle& p : tracker.particles()) {
    const Eigen::Vector3d pc = o.cam_from_world * p.position;
    EXPECT_GE(pc.z(), 4.0 - 1e-9);
    EXPECT_LE(pc.z(), 12.0 + 1e-9);
    EXPECT_LT((pc.hnormalized() - o.xy).norm(), 1e-9);  // on the ray
    // Ground-plane cue: velocity parallel to the ground, speed within the prior.
    EXPECT_NEAR(p.linear_velocity.z(), 0.0, 1e-12);
    EXPECT_LE(p.linear_velocity.norm(), options.init_speed_max + 1e-9);
    mean += pc.z() / 300.0;
  }
  EXPECT_NEAR(mean, 8.0, 0.5);  // uniform in [4, 12]
  const BotEstimate e = tracker.Estimate();
  EXPECT_TRUE(e.valid);
  EXPECT_FALSE(e.velocity_initialized);
  EXPECT_FALSE(e.reliable);
  EXPECT_NEAR(e.depth_sigma, 8.0 / std::sqrt(12.0), 0.5);
  EXPECT_EQ(static_cast<int>(e.particle_samples.size()), options.num_output_samples);
  EXPECT_FALSE(e.has_orientation);
  EXPECT_NEAR(e.pose_covariance(3, 3), M_PI * M_PI, 1e-12);  // unknown rotation
}

// Sec. 5.1.2: a previously static object starts from its mapped depth.
TEST(BearingOnlyTracker, PreviouslyStaticObjectStartsAtItsMappedDepth) {
  BearingOnlyTracker tracker(SmallOptions(), 3);
  const Eigen::Vector3d point(12, -1, 0.5);
  const BotObservation o = Observe(point, 0.0);
  ASSERT_TRUE(tracker.InitializeFromPoint(o, point, 0.3).ok());
  const BotEstimate e = tracker.Estimate();
  const double d = Depth(o.cam_from_world, point);
  EXPECT_NEAR(e.depth, d, 0.1);
  EXPECT_NEAR(e.depth_sigma, 0.3, 0.06);
  EXPECT_LT((e.world_from_object.translation - point).norm(), 0.15);
  // Without a sigma: a share of the depth.
  BearingOnlyTracker ratio(SmallOptions(), 3);
  ASSERT_TRUE(ratio.InitializeFromPoint(o, point).ok());
  EXPECT_NEAR(ratio.Estimate().depth_sigma, SmallOptions().static_depth_sigma_ratio * d, 0.15);
  EXPECT_FALSE(ratio.InitializeFromPoint(o, Eigen::Vector3d(-5, 0, 1)).ok());  // behind
}

// Two trackers with the same seed and inputs agree to the bit; another object id differs.
TEST(BearingOnlyTracker, Deterministic) {
  const auto run = [](int64_t id) {
    BearingOnlyTracker tracker(SmallOptions(), id);
    Eigen::Vector3d target(10, 2, 0.8);
    const Eigen::Vector3d velocity(0.5, -1.0, 0.0);
    EXPECT_TRUE(tracker.Initialize(Observe(target, 0.0)).ok());
    for (int k = 1; k <= 30; ++k) {
      const double t = k / 30.0;
      EXPECT_TRUE(tracker.Update(Observe(target + t * velocity, t)).ok());
    }
    return tracker.particles();
  };
  const std::vector<BotParticle> a = run(5), b = run(5), c = run(6);
  ASSERT_EQ(a.size(), b.size());
  bool all_equal = true, any_differs = false;
  for (size_t i = 0; i < a.size(); ++i) {
    all_equal = all_equal && a[i].position == b[i].position &&
                a[i].linear_velocity == b[i].linear_velocity && a[i].log_weight == b[i].log_weight;
    any_differs = any_differs || a[i].position != c[i].position;
  }
  EXPECT_TRUE(all_equal);
  EXPECT_TRUE(any_differs);
}

TEST(BearingOnlyTracker, SeatsVelocitiesThatFollowTheBearing) {
  BearingOnlyTracker tracker(SmallOptions(), 2);
  const Eigen::Vector3d start(9, 3, 0.8);
  const Eigen::Vector3d velocity(0.0, -1.2, 0.0);
  ASSERT_TRUE(tracker.Initialize(Observe(start, 0.0)).ok());
  for (int k = 1; k <= 15; ++k) {
    const double t = k / 30.0;
    ASSERT_TRUE(tracker.Update(Observe(start + t * velocity, t)).ok());
  }
  EXPECT_TRUE(tracker.velocity_initialized());
  const BotEstimate e = tracker.Estimate();
  EXPECT_TRUE(e.velocity_initialized);
  // Every particle projects close to the bearing, and moves parallel to the ground.
  const BotObservation last = Observe(start + 0.5 * velocity, 0.5);
  for (const BotParticle& p : tracker.particles()) {
    EXPECT_LT(((last.cam_from_world * p.position).hnormalized() - last.xy).norm() * 500.0, 15.0);
    EXPECT_NEAR(p.linear_velocity.z(), 0.0, 1e-9);
  }
  EXPECT_GT(e.effective_sample_size, 0.0);
  EXPECT_LE(e.effective_sample_size, 300.0 + 1e-9);
}

TEST(BearingOnlyTracker, BearingFarFromEveryParticleMovesThemOntoTheRay) {
  BearingOnlyTracker tracker(SmallOptions(), 4);
  const Eigen::Vector3d target(10, 0, 0.8);
  ASSERT_TRUE(tracker.Initialize(Observe(target, 0.0)).ok());
  for (int k = 1; k <= 12; ++k) ASSERT_TRUE(tracker.Update(Observe(target, k / 30.0)).ok());
  // The reference point jumps by 3 units sideways (e.g. a wrong association).
  const BotObservation jump = Observe(target + Eigen::Vector3d(0, 3, 0), 13 / 30.0);
  ASSERT_TRUE(tracker.Update(jump).ok());
  EXPECT_EQ(tracker.stats().recoveries, 1);
  for (const BotParticle& p : tracker.particles()) {
    EXPECT_LT(((jump.cam_from_world * p.position).hnormalized() - jump.xy).norm(), 1e-9);
  }
}

TEST(BearingOnlyTracker, PredictsWithoutBearingAndRescales) {
  BearingOnlyTracker tracker(SmallOptions(), 8);
  const Eigen::Vector3d start(10, 1, 0.8);
  const Eigen::Vector3d velocity(1.0, 0.0, 0.0);
  ASSERT_TRUE(tracker.Initialize(Observe(start, 0.0)).ok());
  for (int k = 1; k <= 20; ++k) {
    const double t = k / 30.0;
    ASSERT_TRUE(tracker.Update(Observe(start + t * velocity, t)).ok());
  }
  const BotEstimate before = tracker.Estimate();
  ASSERT_TRUE(tracker.Predict(before.utime + 500000).ok());
  const BotEstimate after = tracker.Estimate();
  EXPECT_EQ(after.utime, before.utime + 500000);
  EXPECT_LT((after.world_from_object.translation -
             (before.world_from_object.translation + 0.5 * before.linear_velocity))
                .norm(),
            0.2 * before.depth);
  EXPECT_EQ(tracker.stats().predictions, 1);
  EXPECT_FALSE(tracker.Predict(before.utime).ok());  // backwards

  const BotEstimate e = tracker.Estimate();
  tracker.RescaleWorld(2.0);
  const BotEstimate r = tracker.Estimate();
  EXPECT_LT((r.world_from_object.translation - 2.0 * e.world_from_object.translation).norm(), 1e-9);
  EXPECT_LT((r.linear_velocity - 2.0 * e.linear_velocity).norm(), 1e-9);
  EXPECT_NEAR(r.depth, 2.0 * e.depth, 1e-9);
}

TEST(BearingOnlyTracker, PredictedVolumesOverTheHorizon) {
  BearingOnlyTracker tracker(SmallOptions(), 9);
  const Eigen::Vector3d start(10, 1, 0.8);
  ASSERT_TRUE(tracker.Initialize(Observe(start, 0.0)).ok());
  ObjectExtent extent;
  extent.valid = true;
  extent.size = Eigen::Vector3d(0.5, 0.6, 1.7);
  const std::vector<PredictedVolume> volumes = tracker.PredictVolumes(extent);
  ASSERT_EQ(volumes.size(), 5u);  // 0, 0.25, 0.5, 0.75, 1 s
  for (size_t i = 0; i < volumes.size(); ++i) {
    EXPECT_EQ(volumes[i].horizon_us, static_cast<int64_t>(i) * 250000);
    EXPECT_EQ(volumes[i].utime, tracker.utime() + volumes[i].horizon_us);
    EXPECT_GE(volumes[i].probability, 0.9);
    EXPECT_GE(volumes[i].half_extent.minCoeff(), 0.25);
  }
  EXPECT_TRUE(BearingOnlyTracker(SmallOptions(), 1).PredictVolumes(extent).empty());
}

TEST(BearingOnlyTracker, SfmFeedbackGivesOrientationAndRelativeScale) {
  BearingOnlyTracker tracker(SmallOptions(), 11);
  const Eigen::Vector3d start(9, 2, 0.8);
  const Eigen::Vector3d velocity(0.0, -1.0, 0.0);
  const double s_true = 4.0;
  const Eigen::Quaterniond heading(Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitZ()));
  for (int k = 0; k <= 45; ++k) {
    const double t = k / 30.0;
    const Rigid3d world_from_obj(heading, start + t * velocity);
    BotObservation o = Observe(world_from_obj.translation, t);
    const Rigid3d cam_from_obj = o.cam_from_world * world_from_obj;
    SfmObservation sfm;
    sfm.map_id = 1;
    sfm.cam_from_obj = Rigid3d(cam_from_obj.rotation, cam_from_obj.translation / s_true);
    sfm.reference_in_obj = Eigen::Vector3d::Zero();
    o.sfm = sfm;
    ASSERT_TRUE(k == 0 ? tracker.Initialize(o).ok() : tracker.Update(o).ok());
  }
  EXPECT_GT(tracker.stats().sfm_steps, 20);
  const BotEstimate e = tracker.Estimate();
  EXPECT_TRUE(e.has_orientation);
  EXPECT_LT(e.world_from_object.rotation.angularDistance(heading), 1e-6);
  ASSERT_TRUE(e.relative_scale);
  // s = d_BOT / d_SfM for every particle: the same ratio as the depths.
  EXPECT_NEAR(e.relative_scale->scale / s_true,
              e.depth / Depth(CamFromWorld(1.5), start + 1.5 * velocity), 0.05);
  EXPECT_GT(e.relative_scale->sigma, 0.0);
}

}  // namespace

// A static camera sees an object cross at constant velocity: the bearings are the same at
// every depth (depth d with velocity v looks like k d with k v), so the depth distribution
// should stay what it was once the velocities were seated. With the process noise in units,
// a farther hypothesis predicts less bearing jitter and the cloud drifts to the far bound.
double DepthAfterCrossing(bool depth_relative_noise, double* seated_depth) {
  BearingOnlyTrackerOptions options = SmallOptions();
  options.num_particles = 1000;
  options.depth_relative_noise = depth_relative_noise;
  options.cues.ground_plane = false;
  options.cues.size_bound = false;
  BearingOnlyTracker tracker(options, 11);
  const Eigen::Vector3d start(8, 3, 1.0);
  const Eigen::Vector3d velocity(0.0, -1.0, 0.0);
  for (int k = 0; k <= 180; ++k) {
    const double t = k / 30.0;
    BotObservation o = Observe(start + t * velocity, 0.0);
    o.utime = static_cast<int64_t>(std::llround(t * 1e6));
    o.ground_plane.reset();
    o.depth_bound = DepthRange{4.0, 16.0};
    if (k == 0) {
      EXPECT_TRUE(tracker.Initialize(o).ok());
    } else {
      EXPECT_TRUE(tracker.Update(o).ok());
    }
    if (k == 15) *seated_depth = tracker.Estimate().depth;
  }
  return tracker.Estimate().depth;
}

TEST(BearingOnlyTracker, UnobservableDepthDoesNotDriftWithDepthRelativeNoise) {
  double seated_relative = 0.0, seated_absolute = 0.0;
  const double relative = DepthAfterCrossing(true, &seated_relative);
  const double absolute = DepthAfterCrossing(false, &seated_absolute);
  // Measured: 12.50 -> 12.89 with depth-relative noise, 12.79 -> 14.31 without.
  EXPECT_LT(std::abs(relative / seated_relative - 1.0), 0.05);
  EXPECT_GT(absolute / seated_absolute - 1.0, 0.08);
}

}  // namespace mbslam
