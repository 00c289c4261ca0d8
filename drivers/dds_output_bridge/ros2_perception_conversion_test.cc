// Perception outputs -> ROS 2 messages: stamps, quaternion order, markers, pose arrays.

#include "drivers/dds_output_bridge/ros2_perception_conversion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "drivers/dds_output_bridge/test_messages.h"

namespace mbslam {
namespace {

namespace vm = visualization_msgs::msg::dds_;

using testing_util::BitEqual;

// A unit quaternion whose components are all different and not round numbers.
Eigen::Quaterniond OddQuaternion() {
  const double w = 0.1, x = -0.2, y = 0.3;
  return Eigen::Quaterniond(w, x, y, std::sqrt(1.0 - w * w - x * x - y * y));
}

TEST(UtimeToRos2Time, SplitsExactly) {
  int32_t sec = -7;
  uint32_t nanosec = 7;
  ASSERT_TRUE(UtimeToRos2Time(1700000000123456, &sec, &nanosec));
  EXPECT_EQ(sec, 1700000000);
  EXPECT_EQ(nanosec, 123456000u);
  ASSERT_TRUE(UtimeToRos2Time(0, &sec, &nanosec));
  EXPECT_EQ(sec, 0);
  EXPECT_EQ(nanosec, 0u);
  ASSERT_TRUE(UtimeToRos2Time(999999, &sec, &nanosec));
  EXPECT_EQ(sec, 0);
  EXPECT_EQ(nanosec, 999999000u);
  ASSERT_TRUE(UtimeToRos2Time(1000000, &sec, &nanosec));
  EXPECT_EQ(sec, 1);
  EXPECT_EQ(nanosec, 0u);
}

TEST(UtimeToRos2Time, NegativeTimesFloorTheSeconds) {
  // ROS: -1.7 s is {sec: -2, nanosec: 3e8}.
  int32_t sec = 0;
  uint32_t nanosec = 0;
  ASSERT_TRUE(UtimeToRos2Time(-1700000, &sec, &nanosec));
  EXPECT_EQ(sec, -2);
  EXPECT_EQ(nanosec, 300000000u);
  ASSERT_TRUE(UtimeToRos2Time(-1, &sec, &nanosec));
  EXPECT_EQ(sec, -1);
  EXPECT_EQ(nanosec, 999999000u);
}

TEST(UtimeToRos2Time, RejectsTimesOutsideInt32Seconds) {
  constexpr int64_t kMax = std::numeric_limits<int32_t>::max();
  constexpr int64_t kMin = std::numeric_limits<int32_t>::min();
  int32_t sec = 0;
  uint32_t nanosec = 0;
  ASSERT_TRUE(UtimeToRos2Time(kMax * 1000000 + 999999, &sec, &nanosec));
  EXPECT_EQ(sec, kMax);
  EXPECT_EQ(nanosec, 999999000u);
  EXPECT_FALSE(UtimeToRos2Time((kMax + 1) * 1000000, &sec, &nanosec));
  ASSERT_TRUE(UtimeToRos2Time(kMin * 1000000, &sec, &nanosec));
  EXPECT_EQ(sec, kMin);
  EXPECT_EQ(nanosec, 0u);
  EXPECT_FALSE(UtimeToRos2Time(kMin * 1000000 - 1, &sec, &nanosec));
  EXPECT_FALSE(UtimeToRos2Time(std::numeric_limits<int64_t>::max(), &sec, &nanosec));
  EXPECT_FALSE(UtimeToRos2Time(std::numeric_limits<int64_t>::min(), &sec, &nanosec));
}

TEST(SecondsToRos2Duration, SplitsAndRejects) {
  int32_t sec = -1;
  uint32_t nanosec = 1;
  ASSERT_TRUE(SecondsToRos2Duration(1.5, &sec, &nanosec));
  EXPECT_EQ(sec, 1);
  EXPECT_EQ(nanosec, 500000000u);
  ASSERT_TRUE(SecondsToRos2Duration(0.0, &sec, &nanosec));
  EXPECT_EQ(sec, 0);
  EXPECT_EQ(nanosec, 0u);
  ASSERT_TRUE(
      SecondsToRos2Duration(2.9999999999, &sec, &nanosec));  // rounds up into the next second
  EXPECT_EQ(sec, 3);
  EXPECT_EQ(nanosec, 0u);
  EXPECT_FALSE(SecondsToRos2Duration(-0.5, &sec, &nanosec));
  EXPECT_FALSE(SecondsToRos2Duration(std::nan(""), &sec, &nanosec));
  EXPECT_FALSE(SecondsToRos2Duration(1e10, &sec, &nanosec));
}

TEST(ToRos2Pose, QuaternionFieldsAreXyzwBitForBit) {
  Rigid3d pose;
  pose.rotation = OddQuaternion();
  pose.translation = Eigen::Vector3d(1.25, -2.5, 1.0 / 3.0);
  geometry_msgs::msg::dds_::Pose_ msg;
  ToRos2Pose(pose, &msg);
  EXPECT_TRUE(BitEqual(msg.orientation_().x_(), -0.2));
  EXPECT_TRUE(BitEqual(msg.orientation_().y_(), 0.3));
  EXPECT_TRUE(BitEqual(msg.orientation_().z_(), OddQuaternion().z()));
  EXPECT_TRUE(BitEqual(msg.orientation_().w_(), 0.1));
  EXPECT_TRUE(BitEqual(msg.position_().x_(), 1.25));
  EXPECT_TRUE(BitEqual(msg.position_().y_(), -2.5));
  EXPECT_TRUE(BitEqual(msg.position_().z_(), 1.0 / 3.0));
}

TEST(ToRos2PoseStamped, HeaderAndPose) {
  CameraPoseSample pose;
  pose.utime = 1712345678000001;
  pose.world_from_cam.rotation = OddQuaternion();
  pose.world_from_cam.translation = Eigen::Vector3d(0.5, 0.25, -4.0);
  geometry_msgs::msg::dds_::PoseStamped_ msg;
  ASSERT_TRUE(ToRos2PoseStamped(pose, "mbslam_world", &msg).ok());
  EXPECT_EQ(msg.header_().stamp_().sec_(), 1712345678);
  EXPECT_EQ(msg.header_().stamp_().nanosec_(), 1000u);
  EXPECT_EQ(msg.header_().frame_id_(), "mbslam_world");
  EXPECT_EQ(msg.pose_().position_().z_(), -4.0);
  EXPECT_EQ(msg.pose_().orientation_().w_(), 0.1);

  pose.utime = int64_t{1} << 62;
  const Status st = ToRos2PoseStamped(pose, "map", &msg);
  EXPECT_FALSE(st.ok());
  EXPECT_NE(st.message().find("outside ROS 2 time"), std::string::npos) << st.message();
}

ObjectsSample TestObjects() {
  ObjectsSample s;
  s.utime = 1700000000250000;
  s.scale_state = ScaleState::kMetric;
  ObjectSample tracked;
  tracked.id = 1;
  tracked.state = ObjectState::kTracked;
  tracked.world_from_object.rotation = OddQuaternion();
  tracked.world_from_object.translation = Eigen::Vector3d(2.0, 0.5, 8.0);
  tracked.linear_velocity = Eigen::Vector3d(0.6, 0.0, -0.8);  // 1 m/s
  tracked.extent = Eigen::Vector3d(4.2, 1.5, 1.8);
  ObjectSample detected;
  detected.id = 2;
  detected.state = ObjectState::kDetected;
  detected.world_from_object.translation = Eigen::Vector3d(9.0, 9.0, 9.0);
  ObjectSample reconstructed;
  reconstructed.id = 3;
  reconstructed.state = ObjectState::kReconstructed;
  reconstructed.world_from_object.translation = Eigen::Vector3d(-1.0, 0.25, 5.0);
  reconstructed.extent = Eigen::Vector3d(0.6, 0.0, 1.7);  // a zero side: floored at min_scale
  s.objects = {tracked, detected, reconstructed};
  return s;
}

void ExpectHeader(const vm::Marker_& m, const std::string& frame_id) {
  EXPECT_EQ(m.header_().stamp_().sec_(), 1700000000);
  EXPECT_EQ(m.header_().stamp_().nanosec_(), 250000000u);
  EXPECT_EQ(m.header_().frame_id_(), frame_id);
}

void ExpectUnusedFieldsEmpty(const vm::Marker_& m) {
  EXPECT_FALSE(m.frame_locked_());
  EXPECT_TRUE(m.colors_().empty());
  EXPECT_TRUE(m.texture_resource_().empty());
  EXPECT_TRUE(m.texture_().data_().empty());
  EXPECT_TRUE(m.uv_coordinates_().empty());
  EXPECT_TRUE(m.mesh_resource_().empty());
  EXPECT_TRUE(m.mesh_file_().data_().empty());
  EXPECT_FALSE(m.mesh_use_embedded_materials_());
}

TEST(ToRos2MarkerArray, DeleteAllThenBoxArrowAndLabelPerObject) {
  Ros2MarkerOptions options;
  options.lifetime_s = 0.5;
  vm::MarkerArray_ msg;
  ASSERT_TRUE(ToRos2MarkerArray(TestObjects(), "map", options, &msg).ok());
  const std::vector<vm::Marker_>& m = msg.markers_();
  // DELETEALL; object 1: box, arrow, label; object 2 (detected) left out; object 3: box, label.
  ASSERT_EQ(m.size(), 6u);
  for (const vm::Marker_& marker : m) {
    ExpectHeader(marker, "map");
    ExpectUnusedFieldsEmpty(marker);
  }
  EXPECT_EQ(m[0].action_(), vm::Marker_Constants::DELETEALL);
  EXPECT_EQ(m[0].ns_(), "");

  const vm::Marker_& box = m[1];
  EXPECT_EQ(box.ns_(), kObjectBoxNamespace);
  EXPECT_EQ(box.id_(), 1);
  EXPECT_EQ(box.type_(), vm::Marker_Constants::CUBE);
  EXPECT_EQ(box.action_(), vm::Marker_Constants::ADD);
  EXPECT_EQ(box.pose_().position_().x_(), 2.0);
  EXPECT_EQ(box.pose_().position_().y_(), 0.5);
  EXPECT_EQ(box.pose_().position_().z_(), 8.0);
  EXPECT_TRUE(BitEqual(box.pose_().orientation_().x_(), OddQuaternion().x()));
  EXPECT_TRUE(BitEqual(box.pose_().orientation_().y_(), OddQuaternion().y()));
  EXPECT_TRUE(BitEqual(box.pose_().orientation_().z_(), OddQuaternion().z()));
  EXPECT_TRUE(BitEqual(box.pose_().orientation_().w_(), OddQuaternion().w()));
  EXPECT_EQ(box.scale_().x_(), 4.2);
  EXPECT_EQ(box.scale_().y_(), 1.5);
  EXPECT_EQ(box.scale_().z_(), 1.8);
  EXPECT_EQ(box.color_().r_(), ObjectColor(1)[0]);
  EXPECT_EQ(box.color_().g_(), ObjectColor(1)[1]);
  EXPECT_EQ(box.color_().b_(), ObjectColor(1)[2]);
  EXPECT_EQ(box.color_().a_(), 0.5f);
  EXPECT_EQ(box.lifetime_().sec_(), 0);
  EXPECT_EQ(box.lifetime_().nanosec_(), 500000000u);
  EXPECT_TRUE(box.points_().empty());
  EXPECT_TRUE(box.text_().empty());

  const vm::Marker_& arrow = m[2];
  EXPECT_EQ(arrow.ns_(), kObjectVelocityNamespace);
  EXPECT_EQ(arrow.id_(), 1);
  EXPECT_EQ(arrow.type_(), vm::Marker_Constants::ARROW);
  EXPECT_EQ(arrow.pose_().orientation_().w_(), 1.0);  // points are in the header frame
  ASSERT_EQ(arrow.points_().size(), 2u);
  EXPECT_EQ(arrow.points_()[0].x_(), 2.0);
  EXPECT_EQ(arrow.points_()[0].z_(), 8.0);
  EXPECT_EQ(arrow.points_()[1].x_(), 2.0 + 0.6);
  EXPECT_EQ(arrow.points_()[1].y_(), 0.5);
  EXPECT_EQ(arrow.points_()[1].z_(), 8.0 - 0.8);
  EXPECT_EQ(arrow.scale_().x_(), options.arrow_shaft_diameter);
  EXPECT_EQ(arrow.scale_().y_(), options.arrow_head_diameter);
  EXPECT_EQ(arrow.color_().a_(), 1.0f);

  const vm::Marker_& label = m[3];
  EXPECT_EQ(label.ns_(), kObjectLabelNamespace);
  EXPECT_EQ(label.type_(), vm::Marker_Constants::TEXT_VIEW_FACING);
  EXPECT_EQ(label.text_(), "#1 1.00 m/s");
  EXPECT_EQ(label.scale_().z_(), options.label_height);
  EXPECT_EQ(label.pose_().position_().x_(), 2.0);

  const vm::Marker_& box3 = m[4];
  EXPECT_EQ(box3.ns_(), kObjectBoxNamespace);
  EXPECT_EQ(box3.id_(), 3);
  EXPECT_EQ(box3.scale_().x_(), 0.6);
  EXPECT_EQ(box3.scale_().y_(), options.min_scale);
  EXPECT_EQ(box3.scale_().z_(), 1.7);
  EXPECT_EQ(box3.pose_().orientation_().w_(), 1.0);
  EXPECT_EQ(box3.color_().r_(), ObjectColor(3)[0]);
  EXPECT_EQ(m[5].text_(), "#3 0.00 m/s");  // no arrow at zero speed
}

TEST(ToRos2MarkerArray, OptionsSelectTheMarkers) {
  Ros2MarkerOptions options;
  options.include_detected = true;
  options.velocity_arrows = false;
  options.labels = false;
  options.delete_all_first = false;
  ObjectsSample objects = TestObjects();
  objects.scale_state = ScaleState::kUpToScale;
  vm::MarkerArray_ msg;
  ASSERT_TRUE(ToRos2MarkerArray(objects, "world", options, &msg).ok());
  ASSERT_EQ(msg.markers_().size(), 3u);  // three boxes, the detected object included
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(msg.markers_()[i].type_(), vm::Marker_Constants::CUBE);
    EXPECT_EQ(msg.markers_()[i].id_(), objects.objects[i].id);
    EXPECT_EQ(msg.markers_()[i].lifetime_().sec_(), 0);
    EXPECT_EQ(msg.markers_()[i].lifetime_().nanosec_(), 0u);
    ExpectHeader(msg.markers_()[i], "world");
  }
  options.labels = true;
  options.include_detected = false;
  ASSERT_TRUE(ToRos2MarkerArray(objects, "world", options, &msg).ok());
  ASSERT_EQ(msg.markers_().size(), 4u);
  EXPECT_EQ(msg.markers_()[1].text_(), "#1 1.00 units/s");  // not metric yet
}

TEST(ToRos2MarkerArray, EmptyObjectListStillClearsTheDisplay) {
  ObjectsSample none;
  none.utime = 1700000000250000;
  vm::MarkerArray_ msg;
  ASSERT_TRUE(ToRos2MarkerArray(none, "map", Ros2MarkerOptions(), &msg).ok());
  ASSERT_EQ(msg.markers_().size(), 1u);
  EXPECT_EQ(msg.markers_()[0].action_(), vm::Marker_Constants::DELETEALL);
  none.utime = std::numeric_limits<int64_t>::max();
  EXPECT_FALSE(ToRos2MarkerArray(none, "map", Ros2MarkerOptions(), &msg).ok());
}

TEST(ToRos2PoseArray, PublishedObjectsInMessageOrder) {
  geometry_msgs::msg::dds_::PoseArray_ msg;
  ASSERT_TRUE(ToRos2PoseArray(TestObjects(), "map", Ros2MarkerOptions(), &msg).ok());
  EXPECT_EQ(msg.header_().stamp_().sec_(), 1700000000);
  EXPECT_EQ(msg.header_().stamp_().nanosec_(), 250000000u);
  EXPECT_EQ(msg.header_().frame_id_(), "map");
  ASSERT_EQ(msg.poses_().size(), 2u);
  EXPECT_EQ(msg.poses_()[0].position_().z_(), 8.0);
  EXPECT_TRUE(BitEqual(msg.poses_()[0].orientation_().w_(), 0.1));
  EXPECT_EQ(msg.poses_()[1].position_().x_(), -1.0);
  EXPECT_EQ(msg.poses_()[1].orientation_().w_(), 1.0);
  Ros2MarkerOptions all;
  all.include_detected = true;
  ASSERT_TRUE(ToRos2PoseArray(TestObjects(), "map", all, &msg).ok());
  ASSERT_EQ(msg.poses_().size(), 3u);
  EXPECT_EQ(msg.poses_()[1].position_().x_(), 9.0);
}

TEST(ObjectColor, CyclesThroughThePaletteForAnyId) {
  EXPECT_EQ(ObjectColor(1), ObjectColor(9));
  EXPECT_NE(ObjectColor(1), ObjectColor(2));
  EXPECT_EQ(ObjectColor(0), ObjectColor(8));
  EXPECT_EQ(ObjectColor(-7), ObjectColor(1));
}

}  // namespace
}  // namespace mbslam
