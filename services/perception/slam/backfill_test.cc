// Poses of the images before a map exists (initialisation, confirmation) are recovered
// against the new map once it is confirmed (SlamOptions::backfill_max_frames); also
// other tests of a map's life on the same synthetic scene (released tracks, hybrid
// tracking).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <unordered_set>
#include <vector>

#include <opencv2/core.hpp>

#include "services/perception/slam/slam_system.h"
#include "services/perception/tracking/patch_matcher.h"

namespace mbslam {
namespace {

constexpr double kFocal = 500.0;

// A static scene seen by a camera sliding along x at 4 cm per image (cam_from_world of
// image f: translation (-0.04 f, 0, 0)); images 0 and 1 have no labels yet.
struct Scene {
  std::vector<Eigen::Vector3d> points;
  explicit Scene(unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> ux(-0.6, 0.6), uy(-0.45, 0.45), uz(4.0, 10.0);
    for (int i = 0; i < 300; ++i) {
      const double z = uz(rng);
      points.emplace_back(ux(rng) * z, uy(rng) * z, z);
    }
  }
  static Eigen::Vector3d Center(int f) { return Eigen::Vector3d(0.04 * f, 0.0, 0.0); }
  SlamFrame Frame(int f) const { return FrameAt(f, Center(f)); }
  // Image f taken from `center` instead.
  SlamFrame FrameAt(int f, const Eigen::Vector3d& center) const {
    SlamFrame frame;
    frame.frame_index = f;
    frame.utime = f * 33333;
    frame.focal_px = kFocal;
    for (size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector3d p = points[i] - center;
      SlamObservation o;
      o.track_id = static_cast<int64_t>(i);
      o.xy = p.hnormalized();
      o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
      o.body_id = f < 2 ? -1 : 0;
      o.p_static = f < 2 ? 0.5 : 0.9;
      frame.observations.push_back(o);
    }
    return frame;
  }
};

// The map is updated with every track of `frame` held static.
void UpdateMapAllStatic(SlamSystem* slam, const SlamFrame& frame) {
  std::unordered_map<int64_t, int> labels;
  for (const SlamObservation& o : frame.observations) labels[o.track_id] = 0;
  slam->UpdateMap(frame, labels);
}

TEST(SlamBackfill, EarlierImagesGetTheirPosesWhenTheMapIsConfirmed) {
  const Scene scene(3);
  SlamOptions options;
  options.ba.time_limited = false;  // a loaded machine must not cut the BA short
  options.background_ba = false;
  SlamSystem slam(options);
  std::map<int64_t, Rigid3d> live, backfilled;
  int confirmed_at = -1;
  for (int f = 0; f < 30; ++f) {
    const SlamFrame frame = scene.Frame(f);
    const SlamPose pose = slam.TrackPose(frame);
    if (pose.valid) live[f] = pose.cam_from_world;
    if (!pose.backfilled.empty()) {
      EXPECT_EQ(confirmed_at, -1) << "backfilled twice";
      confirmed_at = f;
      for (const auto& [g, T] : pose.backfilled) backfilled[g] = T;
    }
    UpdateMapAllStatic(&slam, frame);
  }
  ASSERT_GT(confirmed_at, 2);
  // Every image before the first live pose is back-filled, none twice.
  for (int f = 0; f < confirmed_at; ++f) {
    EXPECT_EQ(live.count(f), 0u) << f;
    EXPECT_EQ(backfilled.count(f), 1u) << f;
  }
  for (const auto& [f, T] : backfilled) EXPECT_LT(f, confirmed_at);
  // In the map's gauge (image 0 at the origin, unknown scale) the camera centres lie on
  // the true line at distances proportional to the truth.
  const double scale = (live.at(confirmed_at).Inverse().translation).x() / Scene::Center(confirmed_at).x();
  ASSERT_GT(scale, 0.0);
  for (const auto& [f, T] : backfilled) {
    const Eigen::Vector3d c = T.Inverse().translation / scale;
    EXPECT_NEAR((c - Scene::Center(static_cast<int>(f))).norm(), 0.0, 0.01) << "image " << f;
  }
}

// A new map must track the next images with most of its points (the 3-view check of sec.
// 4.4, SlamOptions::init_confirm_frames, init_confirm_inlier_ratio): when most tracks of
// the image after the initialisation disagree with it (here 60 % jump 6 px), the map is
// dropped, no pose is given, and a new map is made and confirmed later.
TEST(SlamBackfill, AMapTheNextImageContradictsIsDropped) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  SlamSystem slam(options);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI), u01(0.0, 1.0);
  int made_at = -1, dropped_at = -1, confirmed_after_drop = -1;
  for (int f = 0; f < 60; ++f) {
    SlamFrame frame = scene.Frame(f);
    const bool contradict = made_at >= 0 && f == made_at + 1;
    if (contradict) {
      for (SlamObservation& o : frame.observations) {
        if (u01(rng) > 0.6) continue;
        const double a = angle(rng);
        o.xy += 6.0 / kFocal * Eigen::Vector2d(std::cos(a), std::sin(a));
        o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
      }
    }
    const SlamPose pose = slam.TrackPose(frame);
    if (made_at < 0 && slam.map().num_keyframes() >= 2) made_at = f;
    if (contradict) {
      EXPECT_FALSE(pose.valid);
      EXPECT_EQ(slam.map().num_keyframes(), 0u) << "the contradicted map is kept";
      dropped_at = f;
    }
    if (dropped_at >= 0 && f > dropped_at && pose.valid && confirmed_after_drop < 0) confirmed_after_drop = f;
    UpdateMapAllStatic(&slam, frame);
  }
  ASSERT_GE(made_at, 0);
  EXPECT_EQ(dropped_at, made_at + 1);
  EXPECT_GT(confirmed_after_drop, dropped_at) << "no new map after the drop";
}

// The image at which the map was initialised (its second keyframe), or -1; tracks with
// an id of `keep_below` or more end after image `drop_after`.
int InitImage(const Scene& scene, const SlamOptions& options, int drop_after = 1000, int64_t keep_below = 1000) {
  SlamSystem slam(options);
  for (int f = 0; f < 40; ++f) {
    SlamFrame frame = scene.Frame(f);
    if (f > drop_after) {
      auto& obs = frame.observations;
      obs.erase(std::remove_if(obs.begin(), obs.end(), [&](const SlamObservation& o) { return o.track_id >= keep_below; }),
                obs.end());
    }
    slam.TrackPose(frame);
    if (slam.map().num_keyframes() >= 2) return static_cast<int>(std::next(slam.map().keyframes().begin())->second.frame_index);
    UpdateMapAllStatic(&slam, frame);
  }
  return -1;
}

// An acceptable initialisation from a short baseline waits for more parallax while its
// tracks last (SlamOptions::init_good_parallax_deg, init_wait_frames, init_wait_keep_ratio).
TEST(SlamBackfill, ShortBaselineInitialisationWaitsForParallax) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;  // a loaded machine must not cut the BA short
  options.background_ba = false;
  options.init_good_parallax_deg = 0.0;
  const int at_once = InitImage(scene, options);
  ASSERT_GT(at_once, 0);
  options.init_good_parallax_deg = 3.0;
  options.init_wait_frames = 30;
  const int waited = InitImage(scene, options);
  EXPECT_GT(waited, at_once + 2);
  EXPECT_LE(waited, at_once + 30);
  // The wait is bounded by init_wait_frames.
  options.init_good_parallax_deg = 45.0;
  options.init_wait_frames = 5;
  EXPECT_EQ(InitImage(scene, options), at_once + 5);
  // When a third of the tracks end just after the first acceptable pair, it goes ahead.
  options.init_wait_frames = 30;
  EXPECT_EQ(InitImage(scene, options, at_once, 200), at_once + 1);
  // With init_wait_projection_frames the wait ends as soon as the parallax gained per
  // image could not reach the good parallax in time (45 deg: after the 3 images judged),
  // and lasts as long as before where it can (3 deg).
  options.init_wait_projection_frames = 3;
  EXPECT_EQ(InitImage(scene, options), at_once + 3);
  options.init_good_parallax_deg = 3.0;
  EXPECT_EQ(InitImage(scene, options), waited);
}

// The tracks of the `count` points nearest the camera.
std::vector<int64_t> NearestTracks(const Scene& scene, size_t count) {
  std::vector<std::pair<double, int64_t>> by_depth;
  for (size_t i = 0; i < scene.points.size(); ++i) by_depth.emplace_back(scene.points[i].z(), static_cast<int64_t>(i));
  std::sort(by_depth.begin(), by_depth.end());
  std::vector<int64_t> ids;
  for (size_t i = 0; i < std::min(count, by_depth.size()); ++i) ids.push_back(by_depth[i].second);
  return ids;
}

// Image f of the scene with only the tracks of the `count` points nearest the camera
// (those with most parallax): the others have ended.
SlamFrame ThinnedFrame(const Scene& scene, size_t count, int f) {
  std::unordered_set<int64_t> kept;
  for (int64_t id : NearestTracks(scene, count)) kept.insert(id);
  SlamFrame frame = scene.Frame(f);
  auto& obs = frame.observations;
  obs.erase(std::remove_if(obs.begin(), obs.end(), [&](const SlamObservation& o) { return !kept.count(o.track_id); }),
            obs.end());
  return frame;
}

// What the wait for parallax does after image at_once, where an acceptable pair waits
// (SlamOptions::init_wait_fallback), when the images after it are `next`.
struct WaitEnd {
  int64_t second_keyframe = -1;  // image of the map's second keyframe after image at_once + 1 (-1: no map)
  bool next_posed = false;       // image at_once + 1 got a live pose
};
WaitEnd EndWaitWith(const Scene& scene, SlamOptions options, int at_once,
                    const std::function<SlamFrame(int)>& next, int images_after = 1) {
  options.init_good_parallax_deg = 45.0;  // never good enough: the pair at at_once waits
  options.init_wait_frames = 30;
  SlamSystem slam(options);
  WaitEnd out;
  for (int f = 0; f <= at_once + images_after; ++f) {
    const SlamFrame frame = f <= at_once ? scene.Frame(f) : next(f);
    const SlamPose pose = slam.TrackPose(frame);
    if (f <= at_once) {
      EXPECT_EQ(slam.map().num_keyframes(), 0u) << "image " << f << " did not wait";
    } else {
      if (f == at_once + 1) out.next_posed = pose.valid;
      if (slam.map().num_keyframes() >= 2 && out.second_keyframe < 0) {
        out.second_keyframe = std::next(slam.map().keyframes().begin())->second.frame_index;
      }
    }
    UpdateMapAllStatic(&slam, frame);
  }
  return out;
}

// A pair waiting for parallax makes the map when the next image's tracks make none
// (here most tracks end: 45 shared with the reference, below init_min_points); that
// image is then tracked on it. Without the fallback the pair is lost with its tracks.
TEST(SlamBackfill, AWaitingPairMakesTheMapWhenItsTracksEnd) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.init_good_parallax_deg = 0.0;
  const int at_once = InitImage(scene, options);
  ASSERT_GT(at_once, 0);
  // The 45 nearest points' tracks go on (those with most parallax, which the pair
  // triangulated), the others end.
  auto thinned = [&](int f) { return ThinnedFrame(scene, 45, f); };
  const WaitEnd on = EndWaitWith(scene, options, at_once, thinned);
  EXPECT_EQ(on.second_keyframe, at_once);
  EXPECT_TRUE(on.next_posed);
  options.init_wait_fallback = false;
  const WaitEnd off = EndWaitWith(scene, options, at_once, thinned);
  EXPECT_EQ(off.second_keyframe, -1);
  EXPECT_FALSE(off.next_posed);
}

// Without init_wait_through_low_parallax a later pair of the same reference that shows
// too little parallax drops the waiting pair: here the next image is the reference
// image turned by 3 deg about the camera centre (no parallax at all). No map is made
// from the waiting pair, then or when most tracks end in the image after.
TEST(SlamBackfill, WithoutWaitingThroughLowParallaxAWaitingPairIsDropped) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.init_good_parallax_deg = 0.0;
  options.init_wait_through_low_parallax = false;
  const int at_once = InitImage(scene, options);
  ASSERT_GT(at_once, 0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  auto turned = [&](int f) {
    SlamFrame frame = scene.Frame(0);
    frame.frame_index = f;
    frame.utime = f * 33333;
    for (SlamObservation& o : frame.observations) {
      o.xy = (R * o.xy.homogeneous()).hnormalized();
      o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
      o.body_id = 0;
      o.p_static = 0.9;
    }
    return frame;
  };
  // Then most tracks end, which would make the waiting pair the map had it not been
  // dropped.
  auto next = [&](int f) { return f == at_once + 1 ? turned(f) : ThinnedFrame(scene, 45, f); };
  const WaitEnd end = EndWaitWith(scene, options, at_once, next, 2);
  EXPECT_EQ(end.second_keyframe, -1);
  EXPECT_FALSE(end.next_posed);
}

// A camera that sways back after the first acceptable pair (the images after it are
// taken from 60 % of that pair's baseline, turned 2 deg: too little median parallax)
// gives parallax back; that does not contradict the waiting pair
// (SlamOptions::init_wait_through_low_parallax), which makes the map when its wait ends.
// Without the option the first such image drops it, and no map is made.
TEST(SlamBackfill, ParallaxGivenBackKeepsTheWaitingPair) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.init_good_parallax_deg = 0.0;
  const int at_once = InitImage(scene, options);
  ASSERT_GT(at_once, 0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(2.0 * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  auto swayed = [&](int f) {
    SlamFrame frame = scene.FrameAt(f, 0.6 * Scene::Center(at_once));
    for (SlamObservation& o : frame.observations) {
      o.xy = (R * o.xy.homogeneous()).hnormalized();
      o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
    }
    return frame;
  };
  const int after = 8;
  options.init_wait_through_low_parallax = true;
  SlamOptions waiting = options;
  waiting.init_good_parallax_deg = 45.0;  // never good enough: the pair at at_once waits
  waiting.init_wait_frames = 5;
  {
    SlamSystem slam(waiting);
    int64_t made_at = -1, second_keyframe = -1;
    for (int f = 0; f <= at_once + after; ++f) {
      const SlamFrame frame = f <= at_once ? scene.Frame(f) : swayed(f);
      const SlamPose pose = slam.TrackPose(frame);
      if (made_at < 0 && slam.map().num_keyframes() >= 2) {
        made_at = f;
        second_keyframe = std::next(slam.map().keyframes().begin())->second.frame_index;
        EXPECT_TRUE(pose.valid);
      }
      UpdateMapAllStatic(&slam, frame);
    }
    EXPECT_EQ(second_keyframe, at_once);
    EXPECT_EQ(made_at, at_once + 5);
  }
  {
    // Back at the reference: too little image motion to judge a pair at all; the wait
    // still ends init_wait_frames after the first acceptable pair.
    SlamSystem slam(waiting);
    int64_t made_at = -1;
    for (int f = 0; f <= at_once + after; ++f) {
      const SlamFrame frame = f <= at_once ? scene.Frame(f) : scene.FrameAt(f, Scene::Center(0));
      slam.TrackPose(frame);
      if (made_at < 0 && slam.map().num_keyframes() >= 2) made_at = f;
      UpdateMapAllStatic(&slam, frame);
    }
    EXPECT_EQ(made_at, at_once + 5);
  }
  waiting.init_wait_through_low_parallax = false;
  {
    SlamSystem slam(waiting);
    for (int f = 0; f <= at_once + after; ++f) {
      const SlamFrame frame = f <= at_once ? scene.Frame(f) : swayed(f);
      slam.TrackPose(frame);
      UpdateMapAllStatic(&slam, frame);
    }
    EXPECT_EQ(slam.map().num_keyframes(), 0u);
  }
}

// With init_keep_best_pair the pair that waits is the acceptable one with most parallax:
// when the camera sways back after image at_once + 2 (the images after it are taken from
// image at_once's position, still acceptable, with less parallax), the map is made from
// the pair of image at_once + 2 when the wait ends; without it, from the last image's.
TEST(SlamBackfill, TheWaitingPairIsTheOneWithMostParallax) {
  const Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.init_good_parallax_deg = 0.0;
  const int at_once = InitImage(scene, options);
  ASSERT_GT(at_once, 0);
  options.init_good_parallax_deg = 45.0;  // never good enough: the pairs wait
  options.init_wait_frames = 5;
  auto second_keyframe_with = [&](bool keep_best) {
    SlamOptions o = options;
    o.init_keep_best_pair = keep_best;
    SlamSystem slam(o);
    for (int f = 0; f <= at_once + 8; ++f) {
      const SlamFrame frame = f <= at_once + 2 ? scene.Frame(f) : scene.FrameAt(f, Scene::Center(at_once));
      slam.TrackPose(frame);
      if (slam.map().num_keyframes() >= 2) return std::next(slam.map().keyframes().begin())->second.frame_index;
      UpdateMapAllStatic(&slam, frame);
    }
    return int64_t{-1};
  };
  EXPECT_EQ(second_keyframe_with(true), at_once + 2);
  EXPECT_EQ(second_keyframe_with(false), at_once + 5);
}

// Images lost while the map lasts (here the segmentation held every track moving in
// images 25 and 26, so no static correspondence was left for tracking) are resected on
// the same map when tracking comes back at image 27: their poses come with that image's,
// before it, once each.
TEST(SlamBackfill, ImagesLostWhileTheMapLastsArePosedWhenTrackingComesBack) {
  const Scene scene(3);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.hybrid_tracking = false;
  SlamSystem slam(options);
  std::map<int64_t, Rigid3d> backfilled;
  int64_t recovered_at = -1;
  bool tracking_before = false;
  for (int f = 0; f < 32; ++f) {
    SlamFrame frame = scene.Frame(f);
    const bool held_moving = f == 25 || f == 26;
    if (held_moving) {
      for (SlamObservation& o : frame.observations) o.body_id = 1;
    }
    const SlamPose pose = slam.TrackPose(frame);
    if (f == 24) tracking_before = pose.valid;
    if (held_moving) {
      EXPECT_FALSE(pose.valid) << "image " << f;
    }
    if (f > 26 && !pose.backfilled.empty()) {
      EXPECT_EQ(recovered_at, -1) << "back-filled twice";
      recovered_at = f;
      for (const auto& [g, T] : pose.backfilled) {
        EXPECT_TRUE(backfilled.emplace(g, T).second) << "image " << g << " twice";
      }
    }
    UpdateMapAllStatic(&slam, frame);  // the map keeps its points
  }
  ASSERT_TRUE(tracking_before);
  EXPECT_EQ(recovered_at, 27);
  ASSERT_EQ(backfilled.size(), 2u);
  // Up to the map's gauge and scale: the recovered poses sit between their neighbours
  // along the camera's straight path, one step apart.
  const Eigen::Vector3d c25 = backfilled.at(25).Inverse().translation;
  const Eigen::Vector3d c26 = backfilled.at(26).Inverse().translation;
  EXPECT_GT((c26 - c25).norm(), 0.0);
  const std::optional<Rigid3d> t24 = slam.PoseOfFrame(24);
  ASSERT_TRUE(t24.has_value());
  const Eigen::Vector3d c24 = t24->Inverse().translation;
  const double step = (c25 - c24).norm();
  EXPECT_NEAR((c26 - c25).norm(), step, 0.2 * step);
  EXPECT_GT((c26 - c25).dot(c25 - c24), 0.0) << "same direction of travel";
}

// Track 0 slips at image 20 onto another feature, 0.8 m nearer along a nearby line of
// sight, and follows it from then on. `reset_at` >= 0: the SLAM starts a new map there,
// without track 0 for its first 15 images (so that the new map's keyframes, not its
// initialisation, would triangulate it).
struct SlipRun {
  bool mapped_before = false;      // track 0 had a point at image 19
  bool released_at_slip = false;   // image 20's pose released it, its point kept
  bool mapped_again = false;       // it got a point again by image 70
};
SlipRun RunSlip(bool stay_unmapped, int reset_at = -1) {
  Scene scene(5);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.hybrid_tracking = false;
  options.released_tracks_stay_unmapped = stay_unmapped;
  SlamSystem slam(options);
  const Eigen::Vector3d other =
      scene.points[0] * (1.0 - 0.8 / scene.points[0].z()) + Eigen::Vector3d(0.05, 0.0, 0.0);
  SlipRun run;
  int64_t point_before = -1;
  for (int f = 0; f < 70; ++f) {
    if (f == reset_at) slam.Reset();
    SlamFrame frame = scene.Frame(f);
    if (reset_at >= 0 && f >= reset_at && f < reset_at + 15) {
      frame.observations.erase(frame.observations.begin());
    } else if (f >= 20) {
      SlamObservation& o = frame.observations[0];
      o.xy = (other - Scene::Center(f)).hnormalized();
      o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
    }
    if (f == 19) {
      point_before = slam.map().PointOfTrack(0);
      run.mapped_before = point_before >= 0;
    }
    slam.TrackPose(frame);
    if (f == 20) {
      run.released_at_slip = slam.map().PointOfTrack(0) < 0 && slam.map().point(point_before) != nullptr;
    }
    UpdateMapAllStatic(&slam, frame);
    if (f > 20 && slam.map().PointOfTrack(0) >= 0) run.mapped_again = true;
  }
  return run;
}

TEST(SlamReleasedTracks, ATrackThatDriftedOffItsPointIsNotTriangulatedAgain) {
  const SlipRun run = RunSlip(/*stay_unmapped=*/true);
  ASSERT_TRUE(run.mapped_before);
  ASSERT_TRUE(run.released_at_slip);
  EXPECT_FALSE(run.mapped_again);
}

TEST(SlamReleasedTracks, WithoutTheOptionItGetsANewPoint) {
  const SlipRun run = RunSlip(/*stay_unmapped=*/false);
  ASSERT_TRUE(run.mapped_before);
  ASSERT_TRUE(run.released_at_slip);
  EXPECT_TRUE(run.mapped_again);  // the feature it follows now is a consistent static point
}

TEST(SlamReleasedTracks, ANewMapForgetsThem) {
  const SlipRun run = RunSlip(/*stay_unmapped=*/true, /*reset_at=*/30);
  ASSERT_TRUE(run.released_at_slip);
  EXPECT_TRUE(run.mapped_again);  // the new map triangulates it like any other track
}

TEST(SlamBackfill, OffKeepsOnlyLivePoses) {
  const Scene scene(4);
  SlamOptions options;
  options.ba.time_limited = false;  // a loaded machine must not cut the BA short
  options.background_ba = false;
  options.backfill_max_frames = 0;
  SlamSystem slam(options);
  for (int f = 0; f < 30; ++f) {
    const SlamFrame frame = scene.Frame(f);
    EXPECT_TRUE(slam.TrackPose(frame).backfilled.empty());
    slam.UpdateMap(frame, {});
  }
}

}  // namespace
}  // namespace mbslam

namespace mbslam {
namespace {

// From image 30 on, only tracks 0-9 keep their map points; every other point is tracked
// anew every 4 images (new ids, staggered; by image 34 no other track is older than 4
// images): too few map correspondences for a resection,
// the low-texture wall's case. With slam.hybrid_tracking the poses go on from those ten
// and the epipolar geometry of the young tracks, and they follow the truth; without it
// the map is lost.
struct StarvedRun {
  int valid_after_30 = 0;
  int assisted = 0;
  std::vector<int> unposed_after_30;
  double worst_error = 0.0;  // camera centre error after image 30, in units of the truth (m)
};

// The appearance the observations carry (SlamObservation::patch): none, an edge (the
// patch's structure tensor has one large eigenvalue: it slides along the edge) or a
// corner (two).
enum class Patches { kNone, kEdge, kCorner };

cv::Mat MakePatch(Patches kind) {
  cv::Mat p(11, 11, CV_8U);
  for (int y = 0; y < p.rows; ++y) {
    for (int x = 0; x < p.cols; ++x) {
      const bool right = x >= 5, low = y >= 5;
      p.at<uint8_t>(y, x) = kind == Patches::kEdge ? (right ? 200 : 60) : ((right != low) ? 200 : 60);
    }
  }
  return p;
}

StarvedRun RunStarved(bool hybrid, int min_tracking_inliers = 20, Patches patches = Patches::kNone) {
  const Scene scene(7);
  SlamOptions options;
  options.ba.time_limited = false;
  options.background_ba = false;
  options.hybrid_tracking = hybrid;
  options.hybrid_max_frames = 10;
  options.min_tracking_inliers = min_tracking_inliers;
  SlamSystem slam(options);
  StarvedRun run;
  double scale = 0.0;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.5 / kFocal);
  const cv::Mat patch = patches == Patches::kNone ? cv::Mat() : MakePatch(patches);
  for (int f = 0; f < 46; ++f) {
    SlamFrame frame = scene.Frame(f);
    for (SlamObservation& o : frame.observations) o.patch = patch;
    if (f >= 30) {
      for (SlamObservation& o : frame.observations) {
        o.xy += Eigen::Vector2d(noise(rng), noise(rng));  // 0.5 px
        o.uv = o.xy * kFocal + Eigen::Vector2d(320.0, 240.0);
        const int64_t i = o.track_id;
        if (i < 10) continue;
        const int64_t life = (f + i) / 4;  // a new track every 4 images, staggered by point
        if (life == (30 + i) / 4) continue;  // the first ends at its first renewal
        o.track_id = 1000 * (life + 1) + i;
        o.body_id = (f + i) % 4 == 0 ? -1 : 0;  // a new track has no label yet
      }
    }
    const SlamPose pose = slam.TrackPose(frame);
    if (f == 29 && pose.valid) scale = pose.cam_from_world.Inverse().translation.x() / Scene::Center(f).x();
    if (f >= 30 && !pose.valid) run.unposed_after_30.push_back(f);
    if (f >= 30 && pose.valid && scale > 0.0) {
      ++run.valid_after_30;
      run.assisted += pose.epipolar_assisted;
      const Eigen::Vector3d c = pose.cam_from_world.Inverse().translation / scale;
      run.worst_error = std::max(run.worst_error, (c - Scene::Center(f)).norm());
    }
    UpdateMapAllStatic(&slam, frame);
  }
  return run;
}

TEST(SlamHybridTracking, PosesGoOnThroughAStarvedMap) {
  const StarvedRun off = RunStarved(false);
  const StarvedRun on = RunStarved(true);
  EXPECT_LT(off.valid_after_30, 10);
  EXPECT_EQ(off.assisted, 0);
  // Starved from image 34: ten assisted poses (hybrid_max_frames), a loss, and again.
  EXPECT_EQ(on.unposed_after_30, std::vector<int>({44}));
  EXPECT_EQ(on.assisted, 11);
  // Within 4 cm (one step) of the truth over the 0.6 m travelled with 0.5 px of noise:
  // 2.5 cm here, where a resection on the ten map points alone (were ten enough) errs by
  // 2.2 cm. The links keep the pose going; with these short-lived tracks they add little
  // accuracy.
  EXPECT_LT(on.worst_error, 0.04);
}

// Only corner-like tracks are linked (SlamOptions::hybrid_min_corner_ratio): tracks whose
// patches are edges (they slide along them) give no links, and the map is lost as
// without assisted poses; corners are linked like tracks without a patch.
TEST(SlamHybridTracking, EdgeTracksAreNotLinkedCornersAre) {
  ASSERT_LT(PatchCornerRatio(MakePatch(Patches::kEdge)), 0.1);
  ASSERT_GT(PatchCornerRatio(MakePatch(Patches::kCorner)), 0.1);
  const StarvedRun edges = RunStarved(true, 20, Patches::kEdge);
  const StarvedRun corners = RunStarved(true, 20, Patches::kCorner);
  EXPECT_EQ(edges.assisted, 0);
  EXPECT_LT(edges.valid_after_30, 10);
  EXPECT_EQ(corners.assisted, 11);
  EXPECT_EQ(corners.unposed_after_30, std::vector<int>({44}));
  EXPECT_LT(corners.worst_error, 0.04);
}

}  // namespace
}  // namespace mbslam
