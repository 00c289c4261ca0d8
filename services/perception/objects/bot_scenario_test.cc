// The bearing-only tracker on synthetic scenes (bot_simulation.h): a car-like or hand-held
// camera watching a constant-velocity target on the ground, ahead of it (following, the
// degenerate case) or crossing its path. Figures are at 2 s after initialisation, over a
// few fixed seeds (deterministic).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "services/perception/objects/bot_simulation.h"

namespace mbslam {
namespace {

BotCues Cues(bool db, bool gp, bool sb, bool sfm) {
  BotCues c;
  c.depth_bound = db;
  c.ground_plane = gp;
  c.size_bound = sb;
  c.sfm_feedback = sfm;
  return c;
}

struct Figures {
  double pos_err_rel = 0.0;                                     // |estimate - truth| / range at 2 s
  double depth_sigma = 0.0;                                     // (m) at 2 s
  double depth_true = 0.0;                                      // (m) at 2 s
  double scale_err = std::numeric_limits<double>::quiet_NaN();  // |s - s_true| / s_true at 2 s
  double hit_05 = 0.0, hit_1 = 0.0;
};

BotSimSequence Sequence(BotSimCamera camera, BotSimTarget target, uint64_t seed,
                        double wiggle = 1.0) {
  BotSimOptions o;
  o.camera = camera;
  o.target = target;
  o.seed = seed;
  o.wiggle_scale = wiggle;
  BotSimSequence seq;
  EXPECT_TRUE(SimulateBotSequence(o, &seq).ok());
  return seq;
}

Figures Track(const BotSimSequence& seq, const BotCues& cues, int64_t id) {
  BearingOnlyTrackerOptions options;
  options.cues = cues;
  BotRunResult r;
  EXPECT_TRUE(RunBotSequence(seq, options, id, &r).ok());
  Figures f;
  const BotRunFrame& at = r.At(2.0);
  f.pos_err_rel = at.position_error / at.range;
  f.depth_sigma = at.depth_sigma;
  f.depth_true = at.depth_true;
  if (at.relative_scale) {
    f.scale_err = std::abs(*at.relative_scale - seq.options.sfm_relative_scale) /
                  seq.options.sfm_relative_scale;
  }
  f.hit_05 = r.HitRate(500000);
  f.hit_1 = r.HitRate(1000000);
  return f;
}

struct Case {
  BotSimCamera camera;
  BotSimTarget target;
  std::string Name() const {
    return std::string(BotSimCameraName(camera)) + " " + BotSimTargetName(target);
  }
};

const Case kCases[] = {{BotSimCamera::kCar, BotSimTarget::kFollowing},
                       {BotSimCamera::kCar, BotSimTarget::kCrossing},
                       {BotSimCamera::kHandHeld, BotSimTarget::kFollowing},
                       {BotSimCamera::kHandHeld, BotSimTarget::kCrossing}};
constexpr int kSeeds = 5;

// With all cues: position error / range after 2 s of tracking <= 10 % (mean over seeds),
// and the relative scale from the SfM feedback within 10 %.
TEST(BotScenario, AllCuesLocateTheTargetAndItsScaleWithinTenPercent) {
  for (const Case& c : kCases) {
    double err = 0.0, worst = 0.0, scale = 0.0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      const Figures f =
          Track(Sequence(c.camera, c.target, seed), Cues(true, true, true, true), seed);
      err += f.pos_err_rel / kSeeds;
      worst = std::max(worst, f.pos_err_rel);
      ASSERT_FALSE(std::isnan(f.scale_err)) << c.Name();
      scale += f.scale_err / kSeeds;
    }
    std::printf(
        "%s, all cues, 2 s: position error / range %.1f %% (worst %.1f %%), scale error "
        "%.1f %%\n",
        c.Name().c_str(), 100.0 * err, 100.0 * worst, 100.0 * scale);
    EXPECT_LE(err, 0.10) << c.Name();
    EXPECT_LE(worst, 0.30) << c.Name();
    EXPECT_LE(scale, 0.10) << c.Name();
  }
}

// Without cues, a camera moving smoothly (constant velocity) cannot observe the depth: every
// scaled copy of the target's trajectory about the camera's explains the bearings.
TEST(BotScenario, WithoutCuesTheDepthStaysUnobservableForASmoothCamera) {
  for (BotSimTarget target : {BotSimTarget::kFollowing, BotSimTarget::kCrossing}) {
    for (int seed = 1; seed <= 3; ++seed) {
      const Figures f = Track(Sequence(BotSimCamera::kCar, target, seed, /*wiggle=*/0.0),
                              Cues(false, false, false, false), seed);
      EXPECT_GE(f.depth_sigma / f.depth_true, 0.3) << BotSimTargetName(target) << " seed " << seed;
    }
  }
}

// Fig. 6.6: each cue alone reduces the depth standard deviation below the cue-less one,
// and all cues together below each single one.
TEST(BotScenario, EachCueReducesTheDepthSpread) {
  const std::vector<std::pair<std::string, BotCues>> singles = {
      {"depth bound", Cues(true, false, false, false)},
      {"ground plane", Cues(false, true, false, false)},
      {"size bound", Cues(false, false, true, false)},
      {"SfM feedback", Cues(false, false, false, true)}};
  for (const Case& c : kCases) {
    if (c.target != BotSimTarget::kFollowing) continue;  // the degenerate case
    std::vector<BotSimSequence> sequences;
    for (int seed = 1; seed <= kSeeds; ++seed)
      sequences.push_back(Sequence(c.camera, c.target, seed));
    const auto mean_sigma = [&](const BotCues& cues) {
      double sum = 0.0;
      for (size_t i = 0; i < sequences.size(); ++i) {
        sum += Track(sequences[i], cues, static_cast<int64_t>(i + 1)).depth_sigma / kSeeds;
      }
      return sum;
    };
    const double none = mean_sigma(Cues(false, false, false, false));
    const double all = mean_sigma(Cues(true, true, true, true));
    std::printf("%s, depth sigma at 2 s (m): none %.2f, all %.2f", c.Name().c_str(), none, all);
    for (const auto& single : singles) {
      const double sigma = mean_sigma(single.second);
      std::printf(", %s %.2f", single.first.c_str(), sigma);
      EXPECT_LT(sigma, 0.7 * none)
          << c.Name() << ": " << single.first << " " << sigma << " m vs none " << none << " m";
      EXPECT_LT(all, sigma) << c.Name() << ": all " << all << " m vs " << single.first << " "
                            << sigma << " m";
    }
    std::printf("\n");
  }
}

// The predicted volumes at +0.5 s and +1 s contain the true centre of the target in at
// least 90 % of the images.
TEST(BotScenario, PredictedVolumesContainTheTrueCentre) {
  for (const Case& c : kCases) {
    for (int seed = 1; seed <= 3; ++seed) {
      const Figures f =
          Track(Sequence(c.camera, c.target, seed), Cues(true, true, true, true), seed);
      EXPECT_GE(f.hit_05, 0.9) << c.Name() << " seed " << seed;
      EXPECT_GE(f.hit_1, 0.9) << c.Name() << " seed " << seed;
    }
  }
}

TEST(BotScenario, TwoRunsAreIdentical) {
  const BotSimSequence seq = Sequence(BotSimCamera::kHandHeld, BotSimTarget::kCrossing, 4);
  BotRunResult a, b;
  ASSERT_TRUE(RunBotSequence(seq, BearingOnlyTrackerOptions(), 4, &a).ok());
  ASSERT_TRUE(RunBotSequence(seq, BearingOnlyTrackerOptions(), 4, &b).ok());
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t k = 0; k < a.frames.size(); ++k) {
    ASSERT_EQ(a.frames[k].depth_mean, b.frames[k].depth_mean) << k;
    ASSERT_EQ(a.frames[k].depth_sigma, b.frames[k].depth_sigma) << k;
    ASSERT_EQ(a.frames[k].volumes.size(), b.frames[k].volumes.size()) << k;
    for (size_t v = 0; v < a.frames[k].volumes.size(); ++v) {
      ASSERT_EQ(a.frames[k].volumes[v].center, b.frames[k].volumes[v].center);
      ASSERT_EQ(a.frames[k].volumes[v].half_extent, b.frames[k].volumes[v].half_extent);
    }
  }
}

// Sec. 5.1.2: a target that was part of the static map starts at its mapped depth and
// stays there.
TEST(BotScenario, PreviouslyStaticTargetStartsAtItsKnownDepth) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kFollowing, 2);
  BearingOnlyTracker tracker(BearingOnlyTrackerOptions(), 2);
  const BotSimFrame& first = seq.frames.front();
  const double d0 = (first.cam_from_world * first.reference_in_world).z();
  ASSERT_TRUE(tracker.InitializeFromPoint(first.observation, first.reference_in_world).ok());
  const BotEstimate e0 = tracker.Estimate();
  EXPECT_NEAR(e0.depth, d0, 0.02 * d0);
  EXPECT_LT(e0.depth_sigma, 0.07 * d0);
  for (size_t k = 1; k < seq.frames.size() && seq.frames[k].utime <= 2000000; ++k) {
    ASSERT_TRUE(tracker.Update(seq.frames[k].observation).ok());
  }
  const BotSimFrame& at2 = seq.frames[60];
  const BotEstimate e = tracker.Estimate();
  const double range = (at2.cam_from_world.Inverse().translation - at2.reference_in_world).norm();
  EXPECT_LE((e.world_from_object.translation - at2.reference_in_world).norm() / range, 0.10);
}

TEST(BotScenario, GroundPlaneOfTheStaticMap) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing, 1);
  const GroundPlane& g = seq.ground_plane.plane;
  EXPECT_GT(g.normal.z(), std::cos(M_PI / 180.0));
  EXPECT_NEAR(g.offset, 0.0, 0.03);
  EXPECT_GT(seq.ground_plane.inlier_ratio, 0.4);
}

}  // namespace
}  // namespace mbslam
