// ObjectTracking on the synthetic bearing-only scenes (bot_simulation.h): identity kept
// through a re-labelling by the segmentation, prediction while unseen, the units of an
// up-to-scale map, and the accuracy of the estimate it publishes.

#include "services/perception/objects/object_tracking.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "services/perception/objects/bot_simulation.h"

namespace mbslam {
namespace {

BotSimSequence Sequence(BotSimCamera camera, BotSimTarget target, double duration_s = 3.0) {
  BotSimOptions o;
  o.camera = camera;
  o.target = target;
  o.duration_s = duration_s;
  o.seed = 3;
  BotSimSequence seq;
  EXPECT_TRUE(SimulateBotSequence(o, &seq).ok());
  return seq;
}

// The simulated tracks carry no identity: a nearest-neighbour tracker gives them ids.
struct TrackIds {
  std::vector<Eigen::Vector2d> xy;
  std::vector<int64_t> ids;
  int64_t next = 0;
  std::vector<int64_t> Assign(const std::vector<Eigen::Vector2d>& now) {
    std::vector<int64_t> out;
    for (const Eigen::Vector2d& p : now) {
      int64_t id = -1;
      double best = 0.01;  // normalised (5 px at f = 500)
      for (size_t k = 0; k < xy.size(); ++k) {
        const double d = (xy[k] - p).norm();
        if (d < best) {
          best = d;
          id = ids[k];
        }
      }
      out.push_back(id >= 0 ? id : next++);
    }
    xy = now;
    ids = out;
    return out;
  }
};

ObjectFrame FrameOf(const BotSimSequence& seq, size_t i, int segment_id, TrackIds* track_ids = nullptr) {
  const BotSimFrame& f = seq.frames[i];
  ObjectFrame frame;
  frame.utime = f.utime;
  frame.pose_valid = true;
  frame.cam_from_world = f.cam_from_world;
  frame.focal_px = seq.options.focal_px;
  frame.metric = true;
  frame.ground = seq.ground_plane.plane;
  if (f.visible && segment_id > 0) {
    ObjectObservation o;
    o.id = segment_id;
    o.track_xy = f.observation.track_xy;
    if (track_ids) {
      o.track_ids = track_ids->Assign(o.track_xy);
    } else {
      for (size_t k = 0; k < o.track_xy.size(); ++k) o.track_ids.push_back(static_cast<int64_t>(k));
    }
    if (f.observation.depth_bound) o.background_depth = f.observation.depth_bound;
    frame.objects.push_back(o);
  }
  return frame;
}

TEST(ObjectTracking, KeepsIdentityThroughRelabellingAndTracksTheTarget) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing);
  ObjectTracking tracking{ObjectTrackingOptions()};
  int first_id = 0;
  double last_rel_error = -1.0;
  TrackIds ids;
  std::vector<double> errors;
  for (size_t i = 0; i < seq.frames.size(); ++i) {
    // The segmentation re-labels the object half way (new cluster id, same tracks).
    const int segment = i < seq.frames.size() / 2 ? 7 : 12;
    const std::vector<TrackedObject>& out = tracking.Update(FrameOf(seq, i, segment, &ids));
    if (!seq.frames[i].visible) continue;
    ASSERT_EQ(out.size(), 1u) << "frame " << i;
    if (first_id == 0) first_id = out[0].id;
    EXPECT_EQ(out[0].id, first_id) << "frame " << i;
    EXPECT_EQ(out[0].segment_id, segment);
    EXPECT_TRUE(out[0].seen);
    const Eigen::Vector3d cam = seq.frames[i].cam_from_world.Inverse().translation;
    const Eigen::Vector3d truth = seq.frames[i].world_from_target.translation;
    last_rel_error = (out[0].center - truth).norm() / (truth - cam).norm();
    errors.push_back(last_rel_error);
    ASSERT_FALSE(out[0].volumes.empty());
  }
  EXPECT_EQ(tracking.stats().filters_started, 1);
  EXPECT_EQ(tracking.stats().reidentified, 1);
  EXPECT_EQ(tracking.PersistentId(12), first_id);
  // The box centre (reference point + extent offset) / range, with all cues: median over
  // the 3 s and the last image. (The car passes close: its visible face and the tracks on
  // it change, which moves the reference point; measured 0.04 and 0.29.)
  ASSERT_FALSE(errors.empty());
  std::nth_element(errors.begin(), errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2), errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.1);
  EXPECT_LT(last_rel_error, 0.4);
}

TEST(ObjectTracking, PredictsWhileUnseenThenDrops) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kFollowing);
  ObjectTrackingOptions options;
  options.keep_unseen_us = 300000;
  ObjectTracking tracking(options);
  size_t i = 0;
  for (; i < 30; ++i) tracking.Update(FrameOf(seq, i, 3));
  ASSERT_EQ(tracking.size(), 1u);
  // Unseen: predicted (reported, not seen) until keep_unseen_us, then dropped.
  int reported_unseen = 0;
  for (; i < 60; ++i) {
    const std::vector<TrackedObject>& out = tracking.Update(FrameOf(seq, i, 0));
    for (const TrackedObject& t : out) {
      EXPECT_FALSE(t.seen);
      ++reported_unseen;
    }
  }
  EXPECT_GT(reported_unseen, 3);
  EXPECT_LE(reported_unseen, 10);  // 0.3 s at 30 Hz
  EXPECT_EQ(tracking.size(), 0u);
  EXPECT_EQ(tracking.stats().filters_dropped, 1);
}

// Segment ids the filters never took (too few tracks) still get a persistent id, and
// a re-labelled object leaves its old segment id behind: such links are forgotten
// forget_after_us after their segment was last seen, or a long run keeps them all.
TEST(ObjectTracking, ForgetsSegmentLinksOfGoneSegments) {
  ObjectTrackingOptions options;
  options.keep_unseen_us = 300000;
  options.forget_after_us = 2000000;
  ObjectTracking tracking(options);
  ObjectFrame f;
  f.pose_valid = false;  // no filter starts: links only through PersistentId
  int64_t t = 1000000;
  int kept_id = 0;
  for (int i = 0; i < 100; ++i, t += 100000) {  // 10 s at 10 Hz
    f.utime = t;
    f.objects.clear();
    ObjectObservation kept;  // segment 5 is seen throughout
    kept.id = 5;
    f.objects.push_back(kept);
    tracking.Update(f);
    const int id = tracking.PersistentId(5);
    if (kept_id == 0) kept_id = id;
    EXPECT_EQ(id, kept_id) << "image " << i;
    if (i < 10) tracking.PersistentId(100 + i);  // ten short-lived segments in the first second
  }
  // The short-lived ones were last seen 9 s ago (> 2 s): gone; segment 5 stays.
  EXPECT_EQ(tracking.num_segment_links(), 1u);
  EXPECT_EQ(tracking.stats().segment_ids_forgotten, 10);
  EXPECT_EQ(tracking.PersistentId(5), kept_id);
  // A forgotten segment id seen again is a new object.
  EXPECT_NE(tracking.PersistentId(100), kept_id);
  EXPECT_EQ(tracking.num_segment_links(), 2u);
}

TEST(ObjectTracking, MetresPerUnitFromCameraHeight) {
  ObjectTrackingOptions options;
  options.unit_guess_m = 7.0;
  ObjectFrame f;
  f.pose_valid = true;
  // Camera 0.25 units above the ground plane z = 0.
  f.cam_from_world = Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, -0.25));
  GroundPlane g;
  g.normal = Eigen::Vector3d::UnitZ();
  g.offset = 0.0;
  f.ground = g;
  EXPECT_DOUBLE_EQ(ObjectTracking(options).MetresPerUnit(f), 7.0);  // height unknown: the guess
  options.camera_height_m = 1.5;
  EXPECT_NEAR(ObjectTracking(options).MetresPerUnit(f), 6.0, 1e-12);
  f.metric = true;
  EXPECT_DOUBLE_EQ(ObjectTracking(options).MetresPerUnit(f), 1.0);
  f.metric = false;
  f.ground.reset();
  EXPECT_DOUBLE_EQ(ObjectTracking(options).MetresPerUnit(f), 7.0);
}

TEST(ObjectTracking, NewSegmentFarAwayIsANewObject) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing);
  ObjectTracking tracking{ObjectTrackingOptions()};
  for (size_t i = 0; i < 20; ++i) tracking.Update(FrameOf(seq, i, 1));
  ObjectFrame f = FrameOf(seq, 20, 1);
  ObjectObservation other;
  other.id = 2;
  for (int k = 0; k < 10; ++k) {
    other.track_ids.push_back(1000 + k);
    other.track_xy.emplace_back(-0.5 + 0.01 * k, 0.3);  // far from the target's bearing
  }
  f.objects.push_back(other);
  const std::vector<TrackedObject>& out = tracking.Update(f);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NE(out[0].id, out[1].id);
  EXPECT_EQ(tracking.stats().reidentified, 0);
}

// Splits the object's observation in frame i into two segments: tracks with even index
// keep `a`, odd ones go to `b` (flows set when given).
void SplitInto(ObjectFrame* f, int a, int b, std::optional<Eigen::Vector2d> flow_a = std::nullopt,
               std::optional<Eigen::Vector2d> flow_b = std::nullopt) {
  ASSERT_EQ(f->objects.size(), 1u);
  const ObjectObservation whole = f->objects[0];
  ObjectObservation pa, pb;
  pa.id = a;
  pb.id = b;
  for (size_t k = 0; k < whole.track_xy.size(); ++k) {
    ObjectObservation& p = k % 2 == 0 ? pa : pb;
    p.track_ids.push_back(whole.track_ids[k]);
    p.track_xy.push_back(whole.track_xy[k]);
  }
  pa.background_depth = pb.background_depth = whole.background_depth;
  pa.flow_xy = flow_a;
  pb.flow_xy = flow_b;
  f->objects = {pa, pb};
}

TEST(ObjectTracking, SplitObjectKeepsOneIdAndOneFilter) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing);
  ObjectTracking tracking{ObjectTrackingOptions()};
  TrackIds ids;
  int first_id = 0;
  for (size_t i = 0; i < seq.frames.size(); ++i) {
    ObjectFrame f = FrameOf(seq, i, 7, &ids);
    // From a third of the way on, the segmentation splits the object into two clusters.
    if (i >= seq.frames.size() / 3 && f.objects.size() == 1) SplitInto(&f, 7, 9);
    const std::vector<TrackedObject>& out = tracking.Update(f);
    if (!seq.frames[i].visible) continue;
    ASSERT_EQ(out.size(), 1u) << "frame " << i;
    if (first_id == 0) first_id = out[0].id;
    EXPECT_EQ(out[0].id, first_id) << "frame " << i;
    EXPECT_TRUE(out[0].seen);
  }
  EXPECT_EQ(tracking.stats().filters_started, 1);
  EXPECT_EQ(tracking.stats().fragments_merged, 1);
  EXPECT_EQ(tracking.PersistentId(9), first_id);
  EXPECT_EQ(tracking.PersistentId(7), first_id);
}

TEST(ObjectTracking, FragmentMovingDifferentlyIsSplitOff) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing);
  ObjectTracking tracking{ObjectTrackingOptions()};
  TrackIds ids;
  const Eigen::Vector2d flow(0.004, 0.0);  // 2 px per image at f = 500
  size_t i = 0;
  for (; i < 20; ++i) {
    ObjectFrame f = FrameOf(seq, i, 7, &ids);
    if (i >= 10) SplitInto(&f, 7, 9, flow, flow);
    tracking.Update(f);
  }
  ASSERT_EQ(tracking.PersistentId(9), tracking.PersistentId(7));
  EXPECT_EQ(tracking.stats().fragments_merged, 1);
  // Segment 9 now moves the other way: a different object after all.
  ObjectFrame f = FrameOf(seq, i, 7, &ids);
  SplitInto(&f, 7, 9, flow, -flow);
  const std::vector<TrackedObject>& out = tracking.Update(f);
  EXPECT_EQ(tracking.stats().fragments_split, 1);
  EXPECT_NE(tracking.PersistentId(9), tracking.PersistentId(7));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NE(out[0].id, out[1].id);
}

TEST(ObjectTracking, NewClusterOnATrackedObjectJoinsIt) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing);
  const Eigen::Vector2d flow(0.004, 0.001);
  for (const bool same_motion : {true, false}) {
    ObjectTrackingOptions options;
    options.merge_new_clusters = true;
    ObjectTracking tracking(options);
    TrackIds ids;
    size_t i = 0;
    for (; i < 20; ++i) {
      ObjectFrame f = FrameOf(seq, i, 7, &ids);
      f.objects[0].flow_xy = flow;
      tracking.Update(f);
    }
    // New tracks on the object (ids never seen) clustered apart by the segmentation.
    ObjectFrame f = FrameOf(seq, i, 7, &ids);
    f.objects[0].flow_xy = flow;
    ObjectObservation extra;
    extra.id = 11;
    const Eigen::Vector2d c = f.objects[0].track_xy.front();
    for (int k = 0; k < 6; ++k) {
      extra.track_ids.push_back(5000 + k);
      extra.track_xy.push_back(c + Eigen::Vector2d(0.002 * k, 0.001 * (k % 3)));
    }
    extra.flow_xy = same_motion ? Eigen::Vector2d(flow) : Eigen::Vector2d(-flow);
    f.objects.push_back(extra);
    const std::vector<TrackedObject>& out = tracking.Update(f);
    if (same_motion) {
      ASSERT_EQ(out.size(), 1u);
      EXPECT_EQ(tracking.PersistentId(11), tracking.PersistentId(7));
      EXPECT_EQ(tracking.stats().fragments_merged, 1);
      EXPECT_EQ(tracking.stats().filters_started, 1);
    } else {
      ASSERT_EQ(out.size(), 2u);
      EXPECT_NE(tracking.PersistentId(11), tracking.PersistentId(7));
      EXPECT_EQ(tracking.stats().fragments_merged, 0);
    }
  }
}

// The segmentation re-labels the object and the new cluster also took many new tracks:
// it holds all of the object's last tracks, though they are a minority of its own.
TEST(ObjectTracking, ClusterHoldingAnObjectsTracksIsThatObject) {
  const BotSimSequence seq = Sequence(BotSimCamera::kCar, BotSimTarget::kCrossing);
  ObjectTracking tracking{ObjectTrackingOptions()};
  TrackIds ids;
  size_t i = 0;
  for (; i < 20; ++i) tracking.Update(FrameOf(seq, i, 7, &ids));
  ASSERT_EQ(tracking.size(), 1u);
  const int id = tracking.PersistentId(7);
  ObjectFrame f = FrameOf(seq, i, 7, &ids);
  ObjectObservation& o = f.objects[0];
  o.id = 12;
  const size_t n = o.track_ids.size();
  ASSERT_GE(n, 3u);
  for (size_t k = 0; k < 3 * n; ++k) {  // new tracks around the old ones
    o.track_ids.push_back(7000 + static_cast<int64_t>(k));
    o.track_xy.push_back(o.track_xy[k % n] + Eigen::Vector2d(0.002, 0.001 * static_cast<double>(k % 5)));
  }
  const std::vector<TrackedObject>& out = tracking.Update(f);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].id, id);
  EXPECT_EQ(tracking.PersistentId(12), id);
  EXPECT_EQ(tracking.stats().reidentified, 1);
  EXPECT_EQ(tracking.stats().filters_started, 1);
}

}  // namespace
}  // namespace mbslam
