#include "services/perception/lcm_adapters/output_adapter.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

TEST(OutputAdapter, CameraPoseQuaternionIsWxyz) {
  CameraPoseOutput p;
  p.utime = 5;
  p.world_from_cam = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())),
                             Eigen::Vector3d(1, 2, 3));
  p.tracking_state = TrackingState::kOk;
  p.covariance(0, 0) = 0.25;
  const mbslam::camera_pose_t m = ToLcm(p);
  EXPECT_NEAR(m.orientation[0], std::cos(0.25), 1e-12);
  EXPECT_NEAR(m.orientation[3], std::sin(0.25), 1e-12);
  EXPECT_EQ(m.position[2], 3.0);
  EXPECT_EQ(m.tracking_state, mbslam::camera_pose_t::TRACKING_OK);
  EXPECT_EQ(m.covariance[0], 0.25);
}

TEST(OutputAdapter, CountsMatchArrays) {
  FrameResult r;
  r.tracks.resize(3);
  r.tracks[1].has_3d = true;
  r.tracks[1].occluded = true;
  HullOutput h;
  h.body_id = 2;
  h.points = {{0, 0}, {1, 0}, {0, 1}};
  r.hulls.push_back(h);
  ObjectOutput o;
  o.id = 2;
  o.particle_samples.resize(5);
  o.volumes.resize(2);
  r.objects.push_back(o);
  const mbslam::tracks_t t = ToLcmTracks(r);
  EXPECT_EQ(t.num_tracks, 3);
  EXPECT_EQ(t.tracks[1].flags, mbslam::feature_track_t::FLAG_HAS_3D | mbslam::feature_track_t::FLAG_OCCLUDED);
  EXPECT_EQ(t.hulls[0].num_points, 3);
  const mbslam::objects_t objs = ToLcmObjects(r);
  ASSERT_EQ(objs.num_objects, 1);
  EXPECT_EQ(objs.objects[0].num_particle_samples, 5);
  EXPECT_EQ(objs.objects[0].num_volumes, 2);
  // Encodes without error (array lengths consistent).
  std::vector<uint8_t> buf(static_cast<size_t>(objs.getEncodedSize()));
  EXPECT_GT(objs.encode(buf.data(), 0, static_cast<int>(buf.size())), 0);
}

}  // namespace
}  // namespace mbslam
