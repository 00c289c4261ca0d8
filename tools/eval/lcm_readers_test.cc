#include "tools/eval/lcm_readers.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "common/lcm/lcm_log.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/objects_t.hpp"
#include "tools/eval/camera_metrics.h"

namespace mbslam {
namespace eval {
namespace {

void SetPose(const Rigid3d& p, double position[3], double orientation[4]) {
  for (int i = 0; i < 3; ++i) {
    position[i] = p.translation[i];
  }
  orientation[0] = p.rotation.w();
  orientation[1] = p.rotation.x();
  orientation[2] = p.rotation.y();
  orientation[3] = p.rotation.z();
}

TEST(LcmReaders, CameraPosesGroundTruthAndObjects) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("mbslam_eval_log_" + std::to_string(::getpid()) + ".lcmlog"))
                               .string();
  {
    Status st;
    auto log = LcmLogWriter::Open(path, &st);
    ASSERT_TRUE(log) << st.message();
    for (int i = 0; i < 20; ++i) {
      const int64_t t = 5000000 + i * 33333;
      const Rigid3d cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.05 * i, Eigen::Vector3d::UnitY())),
                        Eigen::Vector3d(0.1 * i, 0.02 * i * i, 0.0));
      mbslam::ground_truth_t gt{};
      gt.utime = t;
      gt.frame_seq = i;
      gt.source = "sim:test";
      gt.has_camera = 1;
      SetPose(cam, gt.cam_position, gt.cam_orientation);
      mbslam::body_state_t b{};
      b.id = 4;
      b.name = "person";
      b.extent[0] = 0.4;
      b.extent[1] = 0.5;
      b.extent[2] = 1.75;
      SetPose(Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(5.0, 0.1 * i, 0.875)),
              b.position, b.orientation);
      gt.bodies.push_back(b);
      gt.num_bodies = 1;
      ASSERT_TRUE(log->Write("GROUND_TRUTH", t, gt).ok());

      mbslam::camera_pose_t pose{};
      pose.utime = t + 1000;  // estimates arrive with their image time + 1 ms here
      pose.frame_seq = i;
      // Monocular map units: half scale. Not tracked for the first 4 frames, lost at 10.
      SetPose(Rigid3d(cam.rotation, 0.5 * cam.translation), pose.position, pose.orientation);
      pose.tracking_state = i < 4
                                ? mbslam::camera_pose_t::TRACKING_INITIALIZING
                                : (i == 10 ? mbslam::camera_pose_t::TRACKING_LOST
                                           : (i == 11 ? mbslam::camera_pose_t::TRACKING_RELOCALIZED
                                                      : mbslam::camera_pose_t::TRACKING_OK));
      pose.scale_state = mbslam::camera_pose_t::SCALE_UP_TO_SCALE;
      ASSERT_TRUE(log->Write("PERCEPTION_CAMERA_POSE", pose.utime, pose).ok());

      mbslam::objects_t objs{};
      objs.utime = t;
      objs.frame_seq = i;
      mbslam::object_t o{};
      o.id = 12;
      o.position[0] = 2.5;
      o.position[1] = 0.05 * i;
      o.position[2] = 0.4375;
      o.orientation[0] = 1.0;
      o.depth = 2.5;
      mbslam::predicted_volume_t v{};
      v.utime = t + 300000;
      v.horizon_us = 300000;
      v.center[0] = 2.5;
      v.orientation[0] = 1.0;
      v.half_extent[0] = v.half_extent[1] = v.half_extent[2] = 1.0;
      o.volumes.push_back(v);
      o.num_volumes = 1;
      objs.objects.push_back(o);
      // Detected from the segmentation only: an id and a hull, no position.
      mbslam::object_t detected{};
      detected.id = 13;
      detected.orientation[0] = 1.0;
      objs.objects.push_back(detected);
      objs.num_objects = 2;
      ASSERT_TRUE(log->Write("PERCEPTION_OBJECTS", t, objs).ok());
    }
  }
  GroundTruthLog gt;
  ASSERT_TRUE(ReadGroundTruthLog(path, "GROUND_TRUTH", &gt).ok());
  EXPECT_EQ(gt.source, "sim:test");
  EXPECT_EQ(gt.camera.size(), 20u);
  ASSERT_EQ(gt.bodies.count(4), 1u);
  EXPECT_EQ(gt.bodies.at(4).name, "person");
  EXPECT_EQ(gt.bodies.at(4).poses.size(), 20u);
  EXPECT_NEAR(gt.bodies.at(4).extent.z(), 1.75, 1e-12);

  CameraPoseLog est;
  ASSERT_TRUE(ReadCameraPoseLog(path, "PERCEPTION_CAMERA_POSE", &est).ok());
  EXPECT_EQ(est.num_messages, 20);
  EXPECT_EQ(est.tracked.size(), 15u);  // OK and RELOCALIZED count, INITIALIZING and LOST do not
  EXPECT_DOUBLE_EQ(FractionTracked(est.tracked, gt.camera, 20000), 0.75);
  AteResult ate;
  ASSERT_TRUE(ComputeAte(est.tracked, gt.camera, AteOptions(), &ate).ok());
  EXPECT_LT(ate.translation.rmse, 1e-9);
  EXPECT_NEAR(ate.gt_from_est.scale, 2.0, 1e-9);

  std::map<int, ObjectEstimate> objects;
  int messages = 0;
  ASSERT_TRUE(ReadObjectsLog(path, "PERCEPTION_OBJECTS", &objects, &messages).ok());
  EXPECT_EQ(messages, 20);
  ASSERT_EQ(objects.count(12), 1u);
  EXPECT_EQ(objects.at(12).samples.size(), 20u);
  EXPECT_EQ(objects.at(12).samples[3].volumes.size(), 1u);
  ASSERT_EQ(objects.count(13), 1u);
  EXPECT_TRUE(objects.at(13).samples.empty());
  ObjectMetricsOptions options;
  options.horizon_us = 300000;
  ObjectsEvaluation r;
  ASSERT_TRUE(EvaluateObjects(objects, gt.bodies, gt.camera, ate.gt_from_est, options, &r).ok());
  ASSERT_EQ(r.objects.size(), 1u);
  EXPECT_EQ(r.objects[0].gt_id, 4);
  EXPECT_LT(r.objects[0].position_error.max, 1e-9);
  // Predictions 0.3 s ahead: those beyond the last ground truth (frames 10-19) are
  // not checked; the others (frames 0-9) contain the true centre.
  EXPECT_EQ(r.objects[0].volumes_checked, 10);
  EXPECT_EQ(r.objects[0].volumes_hit, 10);

  int count = 0;
  ASSERT_TRUE(CountLogEvents(path, "PERCEPTION_OBJECTS", &count).ok());
  EXPECT_EQ(count, 20);
  EXPECT_FALSE(ReadGroundTruthLog(path, "NO_SUCH_CHANNEL", &gt).ok());
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
