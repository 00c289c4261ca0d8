// Options of perception_dds_bridge: defaults, checks, topic names, the config file.

#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/config/options_yaml.h"

namespace mbslam {
namespace {

TEST(PerceptionDdsBridgeOptions, DefaultsPass) {
  const PerceptionDdsBridgeOptions options;
  EXPECT_TRUE(options.Check()) << LastOptionError();
  EXPECT_EQ(options.frame_id, "map");
  EXPECT_EQ(options.dds.transport, "udp");
  EXPECT_EQ(options.dds.interfaces, std::vector<std::string>{"127.0.0.1"});
  EXPECT_EQ(options.dds.initial_peers, std::vector<std::string>{"127.0.0.1"});
  EXPECT_EQ(options.channels.perception_camera_pose, "PERCEPTION_CAMERA_POSE");
  EXPECT_EQ(options.channels.perception_objects, "PERCEPTION_OBJECTS");
}

TEST(PerceptionDdsBridgeOptions, TopicNames) {
  EXPECT_EQ(Ros2DdsTopicName("mbslam", "camera_pose"), "rt/mbslam/camera_pose");
  EXPECT_EQ(Ros2DdsTopicName("/mbslam/", "/camera_pose"), "rt/mbslam/camera_pose");
  EXPECT_EQ(Ros2DdsTopicName("robot1/mbslam", "objects"), "rt/robot1/mbslam/objects");
  EXPECT_EQ(Ros2DdsTopicName("", "objects"), "rt/objects");
  EXPECT_EQ(Ros2DdsTopicName("mbslam", ""), "");
  EXPECT_TRUE(IsValidRos2Name("mbslam"));
  EXPECT_TRUE(IsValidRos2Name("/robot_1/mbslam/"));
  EXPECT_FALSE(IsValidRos2Name(""));
  EXPECT_FALSE(IsValidRos2Name("/"));
  EXPECT_FALSE(IsValidRos2Name("a//b"));
  EXPECT_FALSE(IsValidRos2Name("1robot"));
  EXPECT_FALSE(IsValidRos2Name("camera-pose"));
  EXPECT_FALSE(IsValidRos2Name("rt/*"));
}

TEST(PerceptionDdsBridgeOptions, ChecksRejectBadValues) {
  auto fails = [](const std::string& yaml) {
    PerceptionDdsBridgeOptions options;
    const Status st = LoadOptionsFromYamlText(yaml, "", &options);
    return !st.ok();
  };
  EXPECT_TRUE(fails("dds: {transport: multicast}"));
  EXPECT_TRUE(fails("dds: {interfaces: [eth0]}"));
  EXPECT_TRUE(fails("dds: {interfaces: []}"));
  EXPECT_TRUE(fails("dds: {initial_peers: [239.255.0.1x]}"));
  EXPECT_TRUE(fails("dds: {domain_id: 233}"));
  EXPECT_TRUE(fails("dds: {history_depth: 0}"));
  EXPECT_TRUE(fails("topics: {objects: camera_pose}"));  // two types on one topic
  EXPECT_TRUE(fails("topics: {camera_pose: '', objects: '', object_poses: ''}"));
  EXPECT_TRUE(fails("topics: {prefix: 'my-robot'}"));
  EXPECT_TRUE(fails("markers: {alpha: 1.5}"));
  EXPECT_TRUE(fails("markers: {min_scale: 0}"));
  EXPECT_TRUE(fails("frame_id: ''"));
  EXPECT_TRUE(fails("channels: {perception_objects: 'PERCEPTION.*'}"));
  EXPECT_TRUE(fails("no_such_option: 1"));
  EXPECT_FALSE(fails("dds: {transport: shm, interfaces: []}"));  // interfaces matter for udp only
  EXPECT_FALSE(fails("topics: {prefix: '', object_poses: ''}"));
}

// config/perception_dds_bridge.yaml is the defaults, every option listed.
TEST(PerceptionDdsBridgeOptions, ConfigFileIsTheDefaults) {
  const char* source = std::getenv("MBSLAM_SOURCE_DIR");
  const std::string path =
      std::string(source ? source : ".") + "/config/perception_dds_bridge.yaml";
  PerceptionDdsBridgeOptions loaded;
  ASSERT_TRUE(LoadOptionsFromFile(path, &loaded).ok()) << path;
  EXPECT_EQ(OptionsToYaml(loaded), OptionsToYaml(PerceptionDdsBridgeOptions()));
  std::ifstream in(path);
  std::stringstream text;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] != '#') text << line << "\n";
  }
  EXPECT_EQ(text.str(), OptionsToYaml(PerceptionDdsBridgeOptions()));
}

}  // namespace
}  // namespace mbslam
