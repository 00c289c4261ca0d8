// The bridge in one process: LCM messages in on memq://, ROS 2 messages out over Fast
// DDS (shared memory, and UDP on loopback with unicast discovery), received by a
// subscriber built from the same IDL with exact field values; bad messages counted.

#include "drivers/dds_output_bridge/perception_dds_bridge.h"

#include <fastrtps/xmlparser/XMLProfileManager.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>

#include "common/util/time.h"
#include "drivers/dds_output_bridge/ros2_perception_conversion.h"
#include "drivers/dds_output_bridge/ros2_perception_test_reader.h"
#include "drivers/dds_output_bridge/test_messages.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/objects_t.hpp"

namespace mbslam {
namespace {

namespace vm = visualization_msgs::msg::dds_;
using testing_util::BitEqual;
using testing_util::ExpectPoseExact;
using testing_util::TestCameraPose;
using testing_util::TestObjects;

// Fast DDS hands samples between participants of one process directly by default; off,
// so that every sample here crosses the transport under test.
class IntraprocessDeliveryOff : public testing::Environment {
 public:
  void SetUp() override {
    eprosima::fastrtps::LibrarySettingsAttributes settings;
    settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
    eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings);
  }
};
testing::Environment* const kIntraprocessOff =
    testing::AddGlobalTestEnvironment(new IntraprocessDeliveryOff);

// A domain id no other test process uses at the same time (0-232).
int UniqueDomain(int k) { return 30 + (static_cast<int>(getpid()) * 11 + k * 37) % 190; }

class PerceptionDdsBridgeTest : public testing::TestWithParam<const char*> {
 protected:
  void SetUp() override {
    options_.dds.transport = GetParam();
    options_.dds.domain_id = UniqueDomain(std::string(GetParam()) == "shm" ? 1 : 2);
    options_.frame_id = "mbslam_world";
    options_.topics.prefix = "robot/mbslam";
    Status st;
    bus_ = LcmBus::Create("memq://", &st);
    ASSERT_TRUE(bus_) << st.message();
    publisher_ = Ros2PerceptionPublisher::Create(options_.dds, options_.topics, &st);
    ASSERT_TRUE(publisher_) << st.message();
    reader_ = Ros2PerceptionTestReader::Create(options_.dds, options_.topics, &st);
    ASSERT_TRUE(reader_) << st.message();
    bridge_ = std::make_unique<PerceptionDdsBridge>(options_, bus_.get(), publisher_.get());
    ASSERT_TRUE(reader_->WaitForWriters(1, 20 * kUsecPerSec)) << "no discovery over " << GetParam();
    ASSERT_TRUE(publisher_->WaitForReaders(1, 20 * kUsecPerSec))
        << "no discovery over " << GetParam();
  }

  // memq:// delivers on handleTimeout: dispatch everything queued.
  void Dispatch() {
    while (bus_->HandleTimeout(10) > 0) {
    }
  }

  PerceptionDdsBridgeOptions options_;
  std::unique_ptr<LcmBus> bus_;
  std::unique_ptr<Ros2PerceptionPublisher> publisher_;
  std::unique_ptr<Ros2PerceptionTestReader> reader_;
  std::unique_ptr<PerceptionDdsBridge> bridge_;
};

TEST_P(PerceptionDdsBridgeTest, CameraPosesArriveAsPoseStampedExactly) {
  EXPECT_NE(publisher_->description().find(
                "rt/robot/mbslam/camera_pose (geometry_msgs::msg::dds_::PoseStamped_)"),
            std::string::npos)
      << publisher_->description();
  EXPECT_EQ(reader_->type_names(),
            "geometry_msgs::msg::dds_::PoseStamped_ visualization_msgs::msg::dds_::MarkerArray_ "
            "geometry_msgs::msg::dds_::PoseArray_");
  const int n = 30;
  for (int i = 0; i < n; ++i)
    bus_->Publish(options_.channels.perception_camera_pose, TestCameraPose(i));
  Dispatch();
  ASSERT_TRUE(reader_->WaitForSamples(n, 0, 0, 10 * kUsecPerSec));
  const auto poses = reader_->camera_poses();
  ASSERT_EQ(poses.size(), static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const mbslam::camera_pose_t want = TestCameraPose(i);
    const auto& got = poses[static_cast<size_t>(i)];
    EXPECT_EQ(got.header_().stamp_().sec_(), want.utime / 1000000) << i;
    EXPECT_EQ(got.header_().stamp_().nanosec_(),
              static_cast<uint32_t>(want.utime % 1000000) * 1000u)
        << i;
    EXPECT_EQ(got.header_().frame_id_(), "mbslam_world");
    ExpectPoseExact(got.pose_(), want.position, want.orientation);
  }
  EXPECT_EQ(bridge_->camera_pose_counts().received, n);
  EXPECT_EQ(bridge_->camera_pose_counts().published, n);
  EXPECT_EQ(bridge_->bad_total(), 0);
}

TEST_P(PerceptionDdsBridgeTest, ObjectsArriveAsMarkersAndPosesExactly) {
  const mbslam::objects_t in = TestObjects();
  bus_->Publish(options_.channels.perception_objects, in);
  Dispatch();
  ASSERT_TRUE(reader_->WaitForSamples(0, 1, 1, 10 * kUsecPerSec));
  const auto arrays = reader_->objects();
  ASSERT_EQ(arrays.size(), 1u);
  const std::vector<vm::Marker_>& m = arrays[0].markers_();
  // DELETEALL; object 4: box, arrow, label; object 7: box, label (at rest); 9 (detected) left out.
  ASSERT_EQ(m.size(), 6u);
  for (const vm::Marker_& marker : m) {
    EXPECT_EQ(marker.header_().stamp_().sec_(), 1700000000);
    EXPECT_EQ(marker.header_().stamp_().nanosec_(), 500000000u);
    EXPECT_EQ(marker.header_().frame_id_(), "mbslam_world");
  }
  EXPECT_EQ(m[0].action_(), vm::Marker_Constants::DELETEALL);
  const size_t box_index[2] = {1, 4};
  for (int k = 0; k < 2; ++k) {
    const mbslam::object_t& o = in.objects[static_cast<size_t>(k)];
    const vm::Marker_& box = m[box_index[k]];
    EXPECT_EQ(box.ns_(), kObjectBoxNamespace);
    EXPECT_EQ(box.id_(), o.id);
    EXPECT_EQ(box.type_(), vm::Marker_Constants::CUBE);
    EXPECT_EQ(box.action_(), vm::Marker_Constants::ADD);
    ExpectPoseExact(box.pose_(), o.position, o.orientation);
    EXPECT_TRUE(BitEqual(box.scale_().x_(), o.extent[0]));
    EXPECT_TRUE(BitEqual(box.scale_().y_(), o.extent[1]));
    EXPECT_TRUE(BitEqual(box.scale_().z_(), o.extent[2]));
    EXPECT_EQ(box.color_().r_(), ObjectColor(o.id)[0]);
    EXPECT_EQ(box.color_().g_(), ObjectColor(o.id)[1]);
    EXPECT_EQ(box.color_().b_(), ObjectColor(o.id)[2]);
    EXPECT_EQ(box.color_().a_(), static_cast<float>(options_.markers.alpha));
  }
  const vm::Marker_& arrow = m[2];
  EXPECT_EQ(arrow.type_(), vm::Marker_Constants::ARROW);
  EXPECT_EQ(arrow.ns_(), kObjectVelocityNamespace);
  ASSERT_EQ(arrow.points_().size(), 2u);
  EXPECT_EQ(arrow.points_()[0].x_(), 6.0);
  EXPECT_EQ(arrow.points_()[1].x_(), 8.0);  // 2 m/s for 1 s
  EXPECT_EQ(arrow.points_()[1].z_(), 8.0);
  EXPECT_EQ(m[3].text_(), "#4 2.00 m/s");
  EXPECT_EQ(m[5].text_(), "#7 0.00 m/s");

  const auto pose_arrays = reader_->object_poses();
  ASSERT_EQ(pose_arrays.size(), 1u);
  EXPECT_EQ(pose_arrays[0].header_().stamp_().sec_(), 1700000000);
  EXPECT_EQ(pose_arrays[0].header_().stamp_().nanosec_(), 500000000u);
  EXPECT_EQ(pose_arrays[0].header_().frame_id_(), "mbslam_world");
  ASSERT_EQ(pose_arrays[0].poses_().size(), 2u);
  for (size_t k = 0; k < 2; ++k)
    ExpectPoseExact(pose_arrays[0].poses_()[k], in.objects[k].position, in.objects[k].orientation);
  EXPECT_EQ(bridge_->objects_counts().published, 1);
}

TEST_P(PerceptionDdsBridgeTest, BadMessagesAreCountedAndDropped) {
  const std::string& pose_channel = options_.channels.perception_camera_pose;
  const std::string& objects_channel = options_.channels.perception_objects;
  // Undecodable: garbage, a truncated pose, an objects_t on the pose channel.
  const uint8_t garbage[] = {1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12};
  bus_->PublishRaw(pose_channel, garbage, sizeof(garbage));
  const mbslam::camera_pose_t good = TestCameraPose(3);
  std::vector<uint8_t> bytes(static_cast<size_t>(good.getEncodedSize()));
  ASSERT_GT(good.encode(bytes.data(), 0, static_cast<int>(bytes.size())), 0);
  bus_->PublishRaw(pose_channel, bytes.data(), static_cast<unsigned>(bytes.size() - 9));
  bus_->Publish(pose_channel, TestObjects());
  // Invalid: NaN position; a time ROS 2 cannot carry.
  mbslam::camera_pose_t nan_pose = TestCameraPose(4);
  nan_pose.position[2] = std::nan("");
  bus_->Publish(pose_channel, nan_pose);
  mbslam::camera_pose_t far_future = TestCameraPose(5);
  far_future.utime = int64_t{4000000000} * kUsecPerSec;
  bus_->Publish(pose_channel, far_future);
  // Valid but not tracking: skipped.
  mbslam::camera_pose_t lost = TestCameraPose(6);
  lost.tracking_state = mbslam::camera_pose_t::TRACKING_LOST;
  bus_->Publish(pose_channel, lost);
  // An objects message claiming a huge array.
  mbslam::objects_t objects = TestObjects();
  std::vector<uint8_t> obj_bytes(static_cast<size_t>(objects.getEncodedSize()));
  ASSERT_GT(objects.encode(obj_bytes.data(), 0, static_cast<int>(obj_bytes.size())), 0);
  // After the 8-byte fingerprint: utime (8), frame_seq (8), scale_state (1), num_objects (4).
  obj_bytes[8 + 17] = 0x7f;
  bus_->PublishRaw(objects_channel, obj_bytes.data(), static_cast<unsigned>(obj_bytes.size()));
  // An objects message with one invalid object: the others still go out.
  objects.objects[1].extent[0] = std::nan("");
  bus_->Publish(objects_channel, objects);
  // Then a good pose: it is the only one that arrives.
  bus_->Publish(pose_channel, good);
  Dispatch();

  ASSERT_TRUE(reader_->WaitForSamples(1, 1, 1, 10 * kUsecPerSec));
  usleep(200000);  // nothing else is on its way
  const auto poses = reader_->camera_poses();
  ASSERT_EQ(poses.size(), 1u);
  ExpectPoseExact(poses[0].pose_(), good.position, good.orientation);
  const BridgeChannelCounts& c = bridge_->camera_pose_counts();
  EXPECT_EQ(c.received, 7);
  EXPECT_EQ(c.bad, 5);
  EXPECT_EQ(c.skipped, 1);
  EXPECT_EQ(c.published, 1);
  EXPECT_NE(c.last_error.find("outside ROS 2 time"), std::string::npos) << c.last_error;
  const BridgeChannelCounts& o = bridge_->objects_counts();
  EXPECT_EQ(o.received, 2);
  EXPECT_EQ(o.bad, 1);
  EXPECT_EQ(o.invalid_objects, 1);
  EXPECT_EQ(o.published, 1);
  ASSERT_EQ(reader_->object_poses().size(), 1u);
  ASSERT_EQ(reader_->object_poses()[0].poses_().size(), 1u);  // object 7 left out
  EXPECT_EQ(bridge_->bad_total(), 6);
  const std::string summary = bridge_->Summary();
  EXPECT_NE(summary.find("PERCEPTION_CAMERA_POSE: received 7, published 1, bad 5, skipped 1"),
            std::string::npos)
      << summary;
}

INSTANTIATE_TEST_SUITE_P(Transports, PerceptionDdsBridgeTest, testing::Values("shm", "udp"),
                         [](const testing::TestParamInfo<const char*>& info) {
                           return std::string(info.param);
                         });

TEST(PerceptionDdsBridgeTopics, DisabledOutputsAreNotSubscribedOrPublished) {
  PerceptionDdsBridgeOptions options;
  options.dds.transport = "shm";
  options.dds.domain_id = UniqueDomain(3);
  options.topics.objects = "";
  options.topics.object_poses = "";
  Status st;
  auto bus = LcmBus::Create("memq://", &st);
  ASSERT_TRUE(bus) << st.message();
  auto publisher = Ros2PerceptionPublisher::Create(options.dds, options.topics, &st);
  ASSERT_TRUE(publisher) << st.message();
  EXPECT_TRUE(publisher->publishes_camera_pose());
  EXPECT_FALSE(publisher->publishes_objects());
  EXPECT_FALSE(publisher->publishes_object_poses());
  EXPECT_FALSE(publisher->Publish(visualization_msgs::msg::dds_::MarkerArray_()).ok());
  PerceptionDdsBridge bridge(options, bus.get(), publisher.get());
  bus->Publish(options.channels.perception_objects, TestObjects());
  while (bus->HandleTimeout(10) > 0) {
  }
  EXPECT_EQ(bridge.objects_counts().received, 0);
  EXPECT_EQ(publisher->description().find("objects"), std::string::npos)
      << publisher->description();
}

}  // namespace
}  // namespace mbslam
