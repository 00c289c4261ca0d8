// perception_dds_bridge as a process: an LCM log replayed into ROS 2 over shared memory,
// a live bridge on udpm:// with DDS on loopback UDP inside a private network namespace
// (both with exact field values at a subscriber built from the same IDL), help, options,
// exit codes, SIGINT / SIGTERM.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "common/lcm/lcm_bus.h"
#include "common/lcm/lcm_log.h"
#include "common/util/time.h"
#include "drivers/common/exit_codes.h"
#include "drivers/common/test_util.h"
#include "drivers/dds_output_bridge/ros2_perception_conversion.h"
#include "drivers/dds_output_bridge/ros2_perception_test_reader.h"
#include "drivers/dds_output_bridge/test_messages.h"
#include "test/drivers/process_util.h"

namespace mbslam {
namespace {

namespace vm = visualization_msgs::msg::dds_;
using testing_util::BinPath;
using testing_util::ChildProcess;
using testing_util::ExpectPoseExact;
using testing_util::MakeTempDir;
using testing_util::RunProcess;
using testing_util::TestCameraPose;
using testing_util::TestObjects;

int UniqueDomain(int k) { return 30 + (static_cast<int>(getpid()) * 17 + k * 43 + 95) % 190; }

std::string SelfPath() {
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  return n > 0 ? std::string(self, static_cast<size_t>(n)) : std::string();
}

// The poses 0..count-1 and the objects arrived exactly.
void ExpectReceivedExactly(const Ros2PerceptionTestReader& reader, int count,
                           const std::string& frame_id) {
  const auto poses = reader.camera_poses();
  ASSERT_EQ(poses.size(), static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    const mbslam::camera_pose_t want = TestCameraPose(i);
    const auto& got = poses[static_cast<size_t>(i)];
    EXPECT_EQ(got.header_().stamp_().sec_(), want.utime / 1000000) << i;
    EXPECT_EQ(got.header_().stamp_().nanosec_(),
              static_cast<uint32_t>(want.utime % 1000000) * 1000u)
        << i;
    EXPECT_EQ(got.header_().frame_id_(), frame_id);
    ExpectPoseExact(got.pose_(), want.position, want.orientation);
  }
  const mbslam::objects_t objects = TestObjects();
  const auto arrays = reader.objects();
  ASSERT_EQ(arrays.size(), 1u);
  const std::vector<vm::Marker_>& m = arrays[0].markers_();
  ASSERT_EQ(m.size(), 6u);  // DELETEALL; 4: box, arrow, label; 7: box, label
  EXPECT_EQ(m[0].action_(), vm::Marker_Constants::DELETEALL);
  const size_t box_index[2] = {1, 4};
  for (size_t k = 0; k < 2; ++k) {
    const vm::Marker_& box = m[box_index[k]];
    const mbslam::object_t& o = objects.objects[k];
    EXPECT_EQ(box.header_().stamp_().sec_(), 1700000000);
    EXPECT_EQ(box.header_().stamp_().nanosec_(), 500000000u);
    EXPECT_EQ(box.header_().frame_id_(), frame_id);
    EXPECT_EQ(box.ns_(), kObjectBoxNamespace);
    EXPECT_EQ(box.id_(), o.id);
    EXPECT_EQ(box.type_(), vm::Marker_Constants::CUBE);
    ExpectPoseExact(box.pose_(), o.position, o.orientation);
    EXPECT_EQ(box.scale_().x_(), o.extent[0]);
    EXPECT_EQ(box.scale_().y_(), o.extent[1]);
    EXPECT_EQ(box.scale_().z_(), o.extent[2]);
  }
  EXPECT_EQ(m[3].text_(), "#4 2.00 m/s");
  const auto pose_arrays = reader.object_poses();
  ASSERT_EQ(pose_arrays.size(), 1u);
  ASSERT_EQ(pose_arrays[0].poses_().size(), 2u);
  for (size_t k = 0; k < 2; ++k) {
    ExpectPoseExact(pose_arrays[0].poses_()[k], objects.objects[k].position,
                    objects.objects[k].orientation);
  }
}

TEST(PerceptionDdsBridgeCli, HelpPrintConfigAndBadOptions) {
  auto r = RunProcess({BinPath("perception_dds_bridge"), "--help"});
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("geometry_msgs/msg/PoseStamped"), std::string::npos) << r.out;
  // config/perception_dds_bridge.yaml is --print-config below its comment lines.
  r = RunProcess({BinPath("perception_dds_bridge"), "--print-config"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  const char* source = std::getenv("MBSLAM_SOURCE_DIR");
  std::ifstream in(std::string(source ? source : ".") + "/config/perception_dds_bridge.yaml");
  std::stringstream body;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] != '#') body << line << "\n";
  }
  EXPECT_EQ(body.str(), r.out);
  r = RunProcess({BinPath("perception_dds_bridge"), "--config", "config/perception_dds_bridge.yaml",
                  "--print-config", "--prefix", "/robot1/mbslam", "--frame-id", "odom", "--domain",
                  "7"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.out.find("prefix: \"/robot1/mbslam\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("frame_id: \"odom\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("domain_id: 7"), std::string::npos) << r.out;

  r = RunProcess({BinPath("perception_dds_bridge"), "--quiet", "--transport", "multicast"});
  EXPECT_EQ(r.exit_code, kExitUsage);
  r = RunProcess({BinPath("perception_dds_bridge"), "--quiet", "--set", "dds.interfaces=[eth0]"});
  EXPECT_EQ(r.exit_code, kExitUsage);
  r = RunProcess({BinPath("perception_dds_bridge"), "--quiet", "--domain", "300"});
  EXPECT_EQ(r.exit_code, kExitUsage);
  r = RunProcess({BinPath("perception_dds_bridge"), "--quiet", "--no-such-flag"});
  EXPECT_EQ(r.exit_code, kExitUsage);
  r = RunProcess({BinPath("perception_dds_bridge"), "--quiet", "--lcm-url", "nosuch://x"});
  EXPECT_EQ(r.exit_code, kExitOutputError) << r.err;
}

TEST(PerceptionDdsBridgeCli, ReplaysALogIntoRos2OverSharedMemoryExactly) {
  const std::string dir = MakeTempDir("pdb_log");
  const std::string log = dir + "/perception.lcmlog";
  const int count = 40;
  {
    Status st;
    auto writer = LcmLogWriter::Open(log, &st);
    ASSERT_TRUE(writer) << st.message();
    for (int i = 0; i < count; ++i) {
      const mbslam::camera_pose_t pose = TestCameraPose(i);
      ASSERT_TRUE(writer->Write("PERCEPTION_CAMERA_POSE", pose.utime, pose).ok());
      if (i == 15) {
        const mbslam::objects_t objects = TestObjects();
        ASSERT_TRUE(writer->Write("PERCEPTION_OBJECTS", objects.utime, objects).ok());
        const char corrupt[] = "not a camera_pose_t";
        ASSERT_TRUE(
            writer->WriteRaw("PERCEPTION_CAMERA_POSE", pose.utime, corrupt, sizeof(corrupt)).ok());
      }
    }
    writer->Flush();
  }
  DdsOutputOptions dds;
  dds.transport = "shm";
  dds.domain_id = UniqueDomain(1);
  Status st;
  auto reader = Ros2PerceptionTestReader::Create(dds, Ros2TopicOptions(), &st);
  ASSERT_TRUE(reader) << st.message();
  // A log at full speed outruns any reader: the writers keep the whole replay.
  ChildProcess bridge({BinPath("perception_dds_bridge"), "--quiet", "--lcm-url",
                       "file://" + log + "?speed=0", "--transport", "shm", "--domain",
                       std::to_string(dds.domain_id), "--wait-subscribers", "1", "--frame-id",
                       "mbslam_world", "--set", "dds.history_depth=1000"});
  const auto r = bridge.Wait(60.0);
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  ASSERT_TRUE(reader->WaitForSamples(count, 1, 1, 10 * kUsecPerSec));
  ExpectReceivedExactly(*reader, count, "mbslam_world");
  EXPECT_NE(r.err.find("PERCEPTION_CAMERA_POSE: received 41, published 40, bad 1, skipped 0"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("PERCEPTION_OBJECTS: received 1, published 1, bad 0"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("end of input"), std::string::npos) << r.err;
}

TEST(PerceptionDdsBridgeCli, NoSubscriberWithinTheTimeout) {
  const auto r = RunProcess({BinPath("perception_dds_bridge"), "--quiet", "--lcm-url", "memq://",
                             "--transport", "shm", "--domain", std::to_string(UniqueDomain(2)),
                             "--wait-subscribers", "1", "--set", "wait_timeout_s=0.5"},
                            30.0);
  EXPECT_EQ(r.exit_code, kExitInputTimeout) << r.err;
  EXPECT_NE(r.err.find("only 0 subscriber(s)"), std::string::npos) << r.err;
}

TEST(PerceptionDdsBridgeCli, SigintAndSigtermStopALiveBridgeCleanly) {
  for (int signal_number : {SIGINT, SIGTERM}) {
    ChildProcess bridge({BinPath("perception_dds_bridge"), "--quiet", "--lcm-url", "memq://",
                         "--transport", "shm", "--domain", std::to_string(UniqueDomain(3))});
    usleep(700000);
    bridge.Signal(signal_number);
    const auto r = bridge.Wait(10.0);
    EXPECT_EQ(r.exit_code, kExitOk) << r.err;
    EXPECT_NE(r.err.find("stopped by signal"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("PERCEPTION_CAMERA_POSE: received 0, published 0, bad 0"),
              std::string::npos)
        << r.err;
  }
}

TEST(PerceptionDdsBridgeCli, LiveOverUdpmAndLoopbackUdpInsideANetworkNamespace) {
  const auto probe = RunProcess({"test/netns/run_in_netns.sh", "/bin/true"});
  if (probe.exit_code == 77) GTEST_SKIP() << "network namespaces unavailable: " << probe.err;
  ASSERT_EQ(probe.exit_code, 0) << probe.err;
  // This test binary runs again inside the namespace (only lo there), the case below.
  const auto r = RunProcess({"test/netns/run_in_netns.sh", "env", "MBSLAM_PDB_INSIDE_NETNS=1",
                             SelfPath(), "--gtest_filter=PerceptionDdsBridgeInsideNetns.*"},
                            120.0);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("[  PASSED  ] 1 test"), std::string::npos) << r.out;
}

// Runs only inside the namespace made by the test above.
TEST(PerceptionDdsBridgeInsideNetns, LiveLcmToRos2OverLoopbackUdp) {
  if (std::getenv("MBSLAM_PDB_INSIDE_NETNS") == nullptr)
    GTEST_SKIP() << "runs inside a network namespace only";
  const std::string url = "udpm://239.255.76.67:7667?ttl=0";
  Status st;
  auto bus = LcmBus::Create(url, &st);
  ASSERT_TRUE(bus) << st.message();
  DdsOutputOptions dds;  // udp on 127.0.0.1, unicast discovery through 127.0.0.1
  dds.domain_id = UniqueDomain(4);
  Ros2TopicOptions topics;
  topics.prefix = "perception";
  auto reader = Ros2PerceptionTestReader::Create(dds, topics, &st);
  ASSERT_TRUE(reader) << st.message();
  ChildProcess bridge({BinPath("perception_dds_bridge"), "--quiet", "--lcm-url", url, "--transport",
                       "udp", "--domain", std::to_string(dds.domain_id), "--prefix", "perception"});
  // Matched writers: the bridge is up (it subscribes to LCM right after creating them,
  // well within the pause).
  ASSERT_TRUE(reader->WaitForWriters(1, 30 * kUsecPerSec));
  usleep(200000);
  const int count = 20;
  for (int i = 0; i < count; ++i) {
    bus->Publish("PERCEPTION_CAMERA_POSE", TestCameraPose(i));
    if (i == 15) bus->Publish("PERCEPTION_OBJECTS", TestObjects());
    usleep(5000);
  }
  const bool all = reader->WaitForSamples(count, 1, 1, 20 * kUsecPerSec);
  bridge.Signal(SIGTERM);
  const auto r = bridge.Wait(15.0);
  ASSERT_TRUE(all) << r.err;
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  ExpectReceivedExactly(*reader, count, "map");
  EXPECT_NE(r.err.find("PERCEPTION_CAMERA_POSE: received 20, published 20, bad 0"),
            std::string::npos)
      << r.err;
}

}  // namespace
}  // namespace mbslam
