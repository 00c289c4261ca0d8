#include "services/perception/slam/map.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include "common/testing/temp_dir.h"

namespace mbslam {
namespace {

TEST(Map, TracksPointsAndSaveLoadRoundTrip) {
  Map map;
  Keyframe k;
  k.frame_index = 3;
  k.utime = 1000;
  k.cam_from_world = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())), Eigen::Vector3d(1, 2, 3));
  const int64_t kid = map.AddKeyframe(k);
  MapPoint p;
  p.position = Eigen::Vector3d(0.5, -1, 7);
  p.track_id = 42;
  const int64_t pid = map.AddPoint(p);
  map.AddObservation(pid, kid, Eigen::Vector2d(0.1, 0.2));
  EXPECT_EQ(map.PointOfTrack(42), pid);
  map.ReleaseTrack(42);
  EXPECT_EQ(map.PointOfTrack(42), -1);
  const std::string path = testing_util::MakeTestTempDir("map") + "/map.txt";
  ASSERT_TRUE(map.Save(path).ok());
  Map loaded;
  ASSERT_TRUE(loaded.Load(path).ok());
  ASSERT_EQ(loaded.num_points(), 1u);
  ASSERT_EQ(loaded.num_keyframes(), 1u);
  EXPECT_LT((loaded.point(pid)->position - p.position).norm(), 1e-12);
  EXPECT_LT(TranslationDistance(loaded.keyframe(kid)->cam_from_world, k.cam_from_world), 1e-12);
  EXPECT_EQ(loaded.keyframe(kid)->point_ids.size(), 1u);
  map.RemovePoint(pid);
  EXPECT_TRUE(map.keyframe(kid)->point_ids.empty());
  Map bad;
  EXPECT_FALSE(bad.Load("/nonexistent").ok());
}

// Keyframe culling leaves points with fewer than two observations when a track still
// holds them; once the track no longer matches them they must go, or a long run keeps
// every point it ever made (soak with the default configuration).
TEST(Map, RemoveStalePointsDropsUnderObservedPointsNoTrackMatches) {
  Map map;
  const int64_t k0 = map.AddKeyframe(Keyframe());
  const int64_t k1 = map.AddKeyframe(Keyframe());
  auto add = [&](int64_t track, int64_t last_seen, std::vector<int64_t> kfs) {
    MapPoint p;
    p.track_id = track;
    p.last_seen_frame = last_seen;
    const int64_t id = map.AddPoint(p);
    for (int64_t k : kfs) map.AddObservation(id, k, Eigen::Vector2d::Zero());
    return id;
  };
  const int64_t two_views_old = add(-1, 0, {k0, k1});   // well observed: kept however old
  const int64_t one_view_fresh = add(7, 100, {k1});     // its track still matches it: kept
  const int64_t one_view_stale = add(8, 40, {k1});      // track died long ago: removed
  const int64_t no_view_released = add(-1, 100, {});    // no track, no keyframe: removed
  const int64_t no_view_fresh = add(9, 95, {});         // tracked right now: kept
  EXPECT_EQ(map.RemoveStalePoints(/*seen_before_frame=*/70), 2);
  EXPECT_NE(map.point(two_views_old), nullptr);
  EXPECT_NE(map.point(one_view_fresh), nullptr);
  EXPECT_EQ(map.point(one_view_stale), nullptr);
  EXPECT_EQ(map.point(no_view_released), nullptr);
  EXPECT_NE(map.point(no_view_fresh), nullptr);
  // The removed point left its keyframe and its track.
  EXPECT_EQ(map.PointOfTrack(8), -1);
  EXPECT_EQ(map.PointOfTrack(7), one_view_fresh);
  EXPECT_EQ(map.keyframe(k1)->point_ids.size(), 2u);
  EXPECT_EQ(map.num_points(), 3u);
  // Later, the fresh one-view point's track stops matching too.
  EXPECT_EQ(map.RemoveStalePoints(/*seen_before_frame=*/101), 2);
  EXPECT_EQ(map.num_points(), 1u);
  EXPECT_EQ(map.RemoveStalePoints(1000), 0);
}

}  // namespace
}  // namespace mbslam
