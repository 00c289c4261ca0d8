#include "services/perception/slam/map.h"

#include <gtest/gtest.h>
#include <unistd.h>

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
  char dir[] = "/tmp/mbslam_map_XXXXXX";
  const std::string path = std::string(mkdtemp(dir)) + "/map.txt";
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

}  // namespace
}  // namespace mbslam
