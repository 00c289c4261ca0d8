// The bridge in process: Fast DDS (shared memory) and LCM memq://.

#include "drivers/odometry_bridge/odometry_bridge.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <thread>

#include "common/lcm/wire_check.h"
#include "common/util/time.h"
#include "drivers/common/test_util.h"
#include "drivers/common/exit_codes.h"
#include "drivers/odometry_bridge/dds_odometry.h"
#include "drivers/odometry_bridge/test_trajectory.h"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "mbslam/pose_t.hpp"

namespace mbslam {
namespace {

int UniqueDomain(int k) { return 20 + (static_cast<int>(getpid()) * 11 + k * 37 + 100) % 200; }

template <typename Msg>
void Record(LcmBus* bus, const std::string& channel, std::vector<Msg>* out) {
  bus->Subscribe(
      channel,
      [out](const std::string&, const uint8_t* data, size_t size, int64_t) {
        Msg msg{};
        if (DecodeLcmMessage(data, size, &msg).ok()) out->push_back(msg);
      },
      10000);
}

TEST(OdometryBridge, RosOdometryToOdometryAndCameraPosesAtImageTimes) {
  Status st;
  std::unique_ptr<LcmBus> bus = LcmBus::Create("memq://", &st);
  ASSERT_TRUE(bus);
  std::vector<mbslam::odometry_t> odometry;
  std::vector<mbslam::pose_t> camera_poses;
  Record(bus.get(), "ODOMETRY", &odometry);
  Record(bus.get(), "ODOMETRY_CAMERA_POSE", &camera_poses);
  LcmBusSink sink(bus.get());

  OdometryBridgeOptions options;
  options.dds.domain_id = UniqueDomain(1);
  options.dds.reliable = true;
  options.max_messages = 101;
  options.idle_timeout_s = 20.0;
  options.image_sync.enabled = true;
  options.image_sync.max_wait_s = 100.0;
  options.base_from_cam.translation = {0.3, 0.05, 0.8};
  Rigid3d base_from_cam;
  ASSERT_TRUE(options.base_from_cam.Resolve(&base_from_cam).ok());
  OdometryBridge bridge(options, &sink, bus.get());
  Status result;
  std::thread runner([&] { result = bridge.Run(); });

  auto writer = DdsOdometryWriter::Create(options.dds, &st);
  ASSERT_TRUE(writer) << st.message();
  ASSERT_TRUE(writer->WaitForReaders(1, 10 * kUsecPerSec));
  // Images at 30 Hz from 0.1 s before the odometry to 0.1 s after it.
  const ScrewTrajectory screw;
  int images = 0;
  for (int i = 0;; ++i, ++images) {
    const int64_t t = screw.t0_utime - 100000 + (i * 1000000) / 30;
    if (t > screw.t0_utime + 2100000) break;
    mbslam::image_t image{};
    image.utime = t;
    image.seq = i;
    image.camera_name = "front";
    bus->Publish("CAMERA_IMAGE", image);
  }
  // Odometry at 50 Hz for 2 s.
  for (int k = 0; k <= 100; ++k) ASSERT_TRUE(writer->Write(screw.Sample(screw.t0_utime + 20000 * k, k)).ok());
  runner.join();
  ASSERT_TRUE(result.ok()) << result.message();
  while (bus->HandleTimeout(0) > 0) {  // memq: deliver what the bridge published last
  }

  ASSERT_EQ(odometry.size(), 101u);
  for (int k = 0; k <= 100; ++k) {
    const OdometrySample want = screw.Sample(screw.t0_utime + 20000 * k, k);
    const mbslam::odometry_t& got = odometry[static_cast<size_t>(k)];
    EXPECT_EQ(got.utime, want.utime);
    EXPECT_EQ(got.seq, k);
    EXPECT_EQ(got.position[0], want.odom_from_base.translation.x());
    EXPECT_EQ(got.position[2], want.odom_from_base.translation.z());
    EXPECT_EQ(got.orientation[0], want.odom_from_base.rotation.w());
    EXPECT_EQ(got.orientation[1], want.odom_from_base.rotation.x());
    EXPECT_EQ(got.linear_velocity[0], want.linear_velocity.x());
    EXPECT_EQ(got.angular_velocity[2], want.angular_velocity.z());
    EXPECT_EQ(got.pose_covariance[0], -1.0);
  }
  ASSERT_EQ(camera_poses.size(), 61u);
  double worst = 0.0;
  for (const mbslam::pose_t& p : camera_poses) {
    const Rigid3d truth = screw.At(p.utime) * base_from_cam;
    const Rigid3d got(Eigen::Quaterniond(p.orientation[0], p.orientation[1], p.orientation[2], p.orientation[3]),
                      Eigen::Vector3d(p.position[0], p.position[1], p.position[2]));
    worst = std::max(worst, TranslationDistance(got, truth));
    EXPECT_LT(RotationDistance(got, truth), 1e-9);
    EXPECT_EQ(p.target_frame, "odom");
    EXPECT_EQ(p.source_frame, "front");
  }
  EXPECT_LT(worst, 1e-9);
  std::printf("bridge: 101 odometry messages exact; camera pose at %zu image times, max error %.3g m\n",
              camera_poses.size(), worst);
  ASSERT_NE(bridge.sync_stats(), nullptr);
  EXPECT_EQ(bridge.sync_stats()->before_first, 3);
  EXPECT_EQ(bridge.sync_stats()->after_last, images - 64);
}

TEST(OdometryBridge, NoPublisherTimesOutWithItsOwnCode) {
  Status st;
  std::unique_ptr<LcmBus> bus = LcmBus::Create("memq://", &st);
  LcmBusSink sink(bus.get());
  OdometryBridgeOptions options;
  options.dds.domain_id = UniqueDomain(2);
  options.idle_timeout_s = 0.3;
  OdometryBridge bridge(options, &sink, bus.get());
  const int64_t start = MonotonicUtime();
  const Status result = bridge.Run();
  EXPECT_FALSE(result.ok());
  EXPECT_EQ(bridge.exit_code(), kExitInputTimeout);
  EXPECT_NE(result.message().find("0 publishers matched"), std::string::npos) << result.message();
  EXPECT_LT(MonotonicUtime() - start, 5 * kUsecPerSec);
}

TEST(OdometryBridge, LcmPoseInputWithDerivedTwistAndBadSamplesCounted) {
  Status st;
  std::unique_ptr<LcmBus> bus = LcmBus::Create("memq://", &st);
  std::vector<mbslam::odometry_t> odometry;
  Record(bus.get(), "ODOMETRY", &odometry);
  LcmBusSink sink(bus.get());
  OdometryBridgeOptions options;
  options.input = "lcm";
  options.pose_channel = "MOCAP";
  options.max_messages = 5;
  OdometryBridge bridge(options, &sink, bus.get());
  const ScrewTrajectory screw;
  Status result;
  std::thread runner([&] { result = bridge.Run(); });
  usleep(100000);  // let Run subscribe
  auto publish = [&](int64_t utime, const Rigid3d& pose) {
    mbslam::pose_t p{};
    p.utime = utime;
    p.target_frame = "world";
    p.source_frame = "robot";
    for (int i = 0; i < 3; ++i) p.position[i] = pose.translation[i];
    p.orientation[0] = pose.rotation.w();
    p.orientation[1] = pose.rotation.x();
    p.orientation[2] = pose.rotation.y();
    p.orientation[3] = pose.rotation.z();
    bus->Publish("MOCAP", p);
  };
  publish(screw.t0_utime, screw.At(screw.t0_utime));
  publish(screw.t0_utime - 5, screw.At(screw.t0_utime));  // older: dropped
  mbslam::pose_t bad{};
  bad.utime = screw.t0_utime + 1;  // zero quaternion: rejected
  bus->Publish("MOCAP", bad);
  for (int k = 1; k <= 4; ++k) publish(screw.t0_utime + 10000 * k, screw.At(screw.t0_utime + 10000 * k));
  runner.join();
  ASSERT_TRUE(result.ok()) << result.message();
  while (bus->HandleTimeout(0) > 0) {  // memq: deliver what the bridge published last
  }
  ASSERT_EQ(odometry.size(), 5u);
  EXPECT_EQ(odometry[0].frame_id, "world");
  EXPECT_EQ(odometry[0].child_frame_id, "robot");
  EXPECT_NEAR(odometry[3].linear_velocity[0], screw.twist[0], 1e-6);
  EXPECT_NEAR(odometry[3].angular_velocity[2], screw.twist[5], 1e-6);
  EXPECT_EQ(bridge.stats().out_of_order, 1);
  EXPECT_EQ(bridge.stats().rejected, 1);
}

TEST(OdometryBridge, CsvFileToLogAndMissingFiles) {
  const std::string dir = testing_util::MakeTempDir("bridge_csv");
  testing_util::WriteTextFile(dir + "/o.csv",
                              "t,x,y,z,qx,qy,qz,qw,vx\n1.0,0,0,0,0,0,0,1,0.5\n1.1,0.05,0,0,0,0,0,1,0.5\n");
  Status st;
  auto sink = LcmLogSink::Create(dir + "/o.lcmlog", &st);
  ASSERT_TRUE(sink);
  OdometryBridgeOptions options;
  options.input = "csv";
  options.file = dir + "/o.csv";
  {
    OdometryBridge bridge(options, sink.get(), nullptr);
    ASSERT_TRUE(bridge.Run().ok());
    EXPECT_EQ(bridge.stats().published, 2);
  }
  sink.reset();
  std::vector<LcmLogEvent> events;
  ASSERT_TRUE(ReadLcmLog(dir + "/o.lcmlog", &events).ok());
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].timestamp, 1100000);
  mbslam::odometry_t msg{};
  ASSERT_TRUE(DecodeLcmMessage(events[1].data.data(), events[1].data.size(), &msg).ok());
  EXPECT_EQ(msg.position[0], 0.05);
  EXPECT_EQ(msg.linear_velocity[0], 0.5);

  auto sink2 = LcmLogSink::Create(dir + "/p.lcmlog", &st);
  options.file = dir + "/missing.csv";
  OdometryBridge missing(options, sink2.get(), nullptr);
  EXPECT_FALSE(missing.Run().ok());
  EXPECT_EQ(missing.exit_code(), kExitInputNotFound);
  testing_util::WriteTextFile(dir + "/bad.csv", "nonsense\n");
  options.file = dir + "/bad.csv";
  OdometryBridge bad(options, sink2.get(), nullptr);
  EXPECT_FALSE(bad.Run().ok());
  EXPECT_EQ(bad.exit_code(), kExitUsage);
  options.input = "lcm";
  OdometryBridge no_bus(options, sink2.get(), nullptr);
  EXPECT_FALSE(no_bus.Run().ok());
  EXPECT_EQ(no_bus.exit_code(), kExitUsage);
}

}  // namespace
}  // namespace mbslam
