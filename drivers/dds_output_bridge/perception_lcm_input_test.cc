// camera_pose_t / objects_t -> plain structs -> ROS 2: the quaternion order across the
// two boundaries ([w, x, y, z] in LCM, (x, y, z, w) in ROS) and the input checks.

#include "drivers/dds_output_bridge/perception_lcm_input.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drivers/dds_output_bridge/test_messages.h"

namespace mbslam {
namespace {

using testing_util::BitEqual;

mbslam::camera_pose_t TestPose() {
  mbslam::camera_pose_t m{};
  m.utime = 1700000000123456;
  m.frame_seq = 42;
  m.position[0] = 1.5;
  m.position[1] = -0.25;
  m.position[2] = 3.0 / 7.0;
  const double w = 0.7, x = 0.1, y = -0.2;
  m.orientation[0] = w;
  m.orientation[1] = x;
  m.orientation[2] = y;
  m.orientation[3] = std::sqrt(1.0 - w * w - x * x - y * y);
  m.tracking_state = mbslam::camera_pose_t::TRACKING_OK;
  m.scale_state = mbslam::camera_pose_t::SCALE_METRIC;
  return m;
}

TEST(PerceptionLcmInput, CameraPoseQuaternionWxyzBecomesRosXyzw) {
  const mbslam::camera_pose_t m = TestPose();
  CameraPoseSample pose;
  bool renormalised = true;
  ASSERT_TRUE(FromLcm(m, &pose, &renormalised).ok());
  EXPECT_FALSE(renormalised);
  EXPECT_EQ(pose.utime, m.utime);
  EXPECT_EQ(pose.tracking_state, TrackingState::kOk);
  EXPECT_EQ(pose.scale_state, ScaleState::kMetric);
  geometry_msgs::msg::dds_::PoseStamped_ ros;
  ASSERT_TRUE(ToRos2PoseStamped(pose, "map", &ros).ok());
  EXPECT_TRUE(BitEqual(ros.pose_().orientation_().w_(), m.orientation[0]));
  EXPECT_TRUE(BitEqual(ros.pose_().orientation_().x_(), m.orientation[1]));
  EXPECT_TRUE(BitEqual(ros.pose_().orientation_().y_(), m.orientation[2]));
  EXPECT_TRUE(BitEqual(ros.pose_().orientation_().z_(), m.orientation[3]));
  EXPECT_TRUE(BitEqual(ros.pose_().position_().x_(), m.position[0]));
  EXPECT_TRUE(BitEqual(ros.pose_().position_().y_(), m.position[1]));
  EXPECT_TRUE(BitEqual(ros.pose_().position_().z_(), m.position[2]));
  EXPECT_EQ(ros.header_().stamp_().sec_(), 1700000000);
  EXPECT_EQ(ros.header_().stamp_().nanosec_(), 123456000u);
}

TEST(PerceptionLcmInput, QuaternionsKeptNormalisedOrRejected) {
  Eigen::Quaterniond q;
  bool renormalised = false;
  const double exact[4] = {1.0, 0.0, 0.0, 0.0};
  ASSERT_TRUE(QuaternionFromWxyz(exact, &q, &renormalised).ok());
  EXPECT_FALSE(renormalised);
  EXPECT_EQ(q.w(), 1.0);
  const double slightly_off[4] = {0.0, 0.0, 1.001, 0.0};
  ASSERT_TRUE(QuaternionFromWxyz(slightly_off, &q, &renormalised).ok());
  EXPECT_TRUE(renormalised);
  EXPECT_DOUBLE_EQ(q.y(), 1.0);
  const double zero[4] = {0.0, 0.0, 0.0, 0.0};
  EXPECT_FALSE(QuaternionFromWxyz(zero, &q, &renormalised).ok());
  const double nan[4] = {std::nan(""), 0.0, 0.0, 1.0};
  EXPECT_FALSE(QuaternionFromWxyz(nan, &q, &renormalised).ok());
  const double far[4] = {1.0, 0.2, 0.0, 0.0};
  EXPECT_FALSE(QuaternionFromWxyz(far, &q, &renormalised).ok());
}

TEST(PerceptionLcmInput, BadCameraPosesAreRejected) {
  CameraPoseSample pose;
  bool renormalised = false;
  mbslam::camera_pose_t m = TestPose();
  m.position[1] = std::nan("");
  EXPECT_FALSE(FromLcm(m, &pose, &renormalised).ok());
  m = TestPose();
  m.orientation[0] = 0.0;
  EXPECT_FALSE(FromLcm(m, &pose, &renormalised).ok());
  m = TestPose();
  m.tracking_state = 9;
  EXPECT_FALSE(FromLcm(m, &pose, &renormalised).ok());
  m = TestPose();
  m.scale_state = -1;
  EXPECT_FALSE(FromLcm(m, &pose, &renormalised).ok());
}

mbslam::object_t TestObject(int id) {
  mbslam::object_t o{};
  o.id = id;
  o.state = mbslam::object_t::STATE_TRACKED;
  o.position[0] = id;
  o.position[1] = 0.5;
  o.position[2] = 10.0;
  o.orientation[0] = 0.0;  // [w, x, y, z]: 180 degrees about y
  o.orientation[2] = 1.0;
  o.linear_velocity[0] = 1.0;
  o.extent[0] = 4.0;
  o.extent[1] = 1.5;
  o.extent[2] = 1.6;
  return o;
}

TEST(PerceptionLcmInput, ObjectsWithInvalidEntriesKeepTheGoodOnes) {
  mbslam::objects_t m{};
  m.utime = 5000000;
  m.scale_state = mbslam::camera_pose_t::SCALE_UP_TO_SCALE;
  m.objects = {TestObject(1), TestObject(2), TestObject(3), TestObject(4)};
  m.objects[1].extent[2] = -1.0;
  m.objects[2].linear_velocity[1] = std::numeric_limits<double>::infinity();
  m.objects[3].state = 7;
  m.num_objects = 4;
  ObjectsSample objects;
  int invalid = 0, renormalised = 0;
  std::string reason;
  ASSERT_TRUE(FromLcm(m, &objects, &invalid, &reason, &renormalised).ok());
  EXPECT_EQ(invalid, 3);
  EXPECT_NE(reason.find("object 4: unknown state 7"), std::string::npos) << reason;
  ASSERT_EQ(objects.objects.size(), 1u);
  const ObjectSample& o = objects.objects[0];
  EXPECT_EQ(o.id, 1);
  EXPECT_EQ(o.state, ObjectState::kTracked);
  EXPECT_EQ(o.world_from_object.rotation.w(), 0.0);
  EXPECT_EQ(o.world_from_object.rotation.y(), 1.0);
  EXPECT_EQ(o.world_from_object.translation.z(), 10.0);
  EXPECT_EQ(o.extent.x(), 4.0);
  EXPECT_EQ(o.linear_velocity.x(), 1.0);
  EXPECT_EQ(objects.utime, 5000000);
  EXPECT_EQ(objects.scale_state, ScaleState::kUpToScale);

  m.num_objects = 3;  // disagrees with the array
  EXPECT_FALSE(FromLcm(m, &objects, &invalid, &reason, &renormalised).ok());
  m.num_objects = 4;
  m.scale_state = 5;
  EXPECT_FALSE(FromLcm(m, &objects, &invalid, &reason, &renormalised).ok());
}

}  // namespace
}  // namespace mbslam
