#include "services/perception/slam/map.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

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

// Relocalisation needs a point's ORB descriptor and guided matching its patch after a
// reload; version 1 files (without them) still load; a damaged file is refused whole.
TEST(Map, SaveLoadKeepsDescriptorsAndPatchesAndRefusesDamage) {
  Map map;
  Keyframe k;
  k.cam_from_world = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(-0.2, Eigen::Vector3d::UnitY())),
                             Eigen::Vector3d(0, 1, 0));
  const int64_t kid = map.AddKeyframe(k);
  MapPoint described;
  described.position = Eigen::Vector3d(1, 2, 3);
  described.has_descriptor = true;
  for (size_t i = 0; i < described.descriptor.bits.size(); ++i)
    described.descriptor.bits[i] = static_cast<uint8_t>(7 * i + 3);
  described.patch = cv::Mat(11, 11, CV_8UC1);
  for (int i = 0; i < 121; ++i)
    described.patch.at<uint8_t>(i / 11, i % 11) = static_cast<uint8_t>(2 * i);
  const int64_t a = map.AddPoint(described);
  MapPoint plain;
  plain.position = Eigen::Vector3d(-1, 0, 5);
  const int64_t b = map.AddPoint(plain);
  map.AddObservation(a, kid, Eigen::Vector2d(0.1, 0.2));
  map.AddObservation(b, kid, Eigen::Vector2d(-0.3, 0.0));
  const std::string dir = testing_util::MakeTestTempDir("map_descriptors");
  ASSERT_TRUE(map.Save(dir + "/map.txt").ok());
  Map loaded;
  ASSERT_TRUE(loaded.Load(dir + "/map.txt").ok());
  EXPECT_EQ(map.num_described_points(), 1u);
  EXPECT_EQ(loaded.num_described_points(), 1u);
  ASSERT_TRUE(loaded.point(a)->has_descriptor);
  EXPECT_EQ(loaded.point(a)->descriptor.bits, described.descriptor.bits);
  ASSERT_EQ(loaded.point(a)->patch.rows, 11);
  EXPECT_EQ(cv::norm(loaded.point(a)->patch, described.patch, cv::NORM_INF), 0.0);
  EXPECT_FALSE(loaded.point(b)->has_descriptor);
  EXPECT_TRUE(loaded.point(b)->patch.empty());

  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + "/" + name) << text;
    return dir + "/" + name;
  };
  const std::string keyframe = "keyframes 1\n0 3 1000 1 0 0 0 0 0 0 1\n";
  // Version 1: no descriptor, no patch.
  Map v1;
  ASSERT_TRUE(
      v1.Load(write("v1.txt", "mbslam_map 1\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2\n"))
          .ok());
  EXPECT_EQ(v1.num_points(), 1u);
  EXPECT_FALSE(v1.point(4)->has_descriptor);
  const std::string hex(64, 'a');
  const std::vector<std::string> damaged = {
      "mbslam_map 3\n" + keyframe + "points 0\n",  // unknown version
      "mbslam_map 2\n" + keyframe +
          "points 1\n4 nan 2 3 128 1 0 0.1 0.2 - 0\n",                          // non-finite point
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 300 1 0 0.1 0.2 - 0\n",  // grey level
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 9 0.1 0.2 - 0\n",  // missing keyframe
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2 " + hex.substr(1) +
          "g 0\n",                                                                 // bad hex
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2 - 5 00\n",  // short patch
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2 - 99\n",  // patch too large
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2\n",       // truncated
      "mbslam_map 2\nkeyframes 1\n0 3 1000 2 0 0 0 0 0 0 1\npoints 0\n",         // not a rotation
      "mbslam_map 2\n" + keyframe + "points 1\n-4 1 2 3 128 1 0 0.1 0.2 - 0\n",  // negative id
      "mbslam_map 2\n" + keyframe + "points 2\n4 1 2 3 128 0 - 0\n4 1 2 3 128 0 - 0\n",  // id twice
      "mbslam_map 2\n" + keyframe +
          "points 1\n4 1 2 3 128 2 0 0.1 0.2 0 0.1 0.2 - 0\n",  // seen twice
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2 - 4 " +
          std::string(32, '0') + "\n",                                             // even side
      "mbslam_map 2\n" + keyframe + "points 1\n4 1 2 3 128 1 0 0.1 0.2 - 1 7f\n",  // one pixel
      "mbslam_map 2\nkeyframes 1\n4611686018427387904 3 1000 1 0 0 0 0 0 0 1\npoints 0\n",  // id
                                                                                            // too
                                                                                            // large
  };
  for (size_t i = 0; i < damaged.size(); ++i) {
    Map m = loaded;
    EXPECT_FALSE(m.Load(write("bad" + std::to_string(i) + ".txt", damaged[i])).ok()) << damaged[i];
    EXPECT_EQ(m.num_points(), 2u) << "a refused file leaves the map as it was";
  }
  // A well-formed version 2 line with a descriptor and a 5 x 5 patch.
  Map good;
  ASSERT_TRUE(good.Load(write("good.txt", "mbslam_map 2\n" + keyframe +
                                              "points 1\n4 1 2 3 128 1 0 0.1 0.2 " + hex + " 5 7f" +
                                              std::string(48, '1') + "\n"))
                  .ok());
  EXPECT_EQ(good.point(4)->descriptor.bits[0], 0xaa);
  EXPECT_EQ(good.point(4)->patch.at<uint8_t>(0, 0), 0x7f);
  EXPECT_EQ(good.point(4)->patch.at<uint8_t>(4, 4), 0x11);
}

}  // namespace
}  // namespace mbslam
