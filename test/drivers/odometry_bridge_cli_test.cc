// odometry_bridge, ros2_odometry_publisher and handeye_calib as processes: ROS 2
// Odometry over Fast DDS bridged to ODOMETRY with exact field values, file inputs,
// exit codes, and the hand-eye tool end to end.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>

#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "drivers/common/exit_codes.h"
#include "drivers/common/pose_files.h"
#include "drivers/common/test_util.h"
#include "drivers/odometry_bridge/odometry_bridge_options.h"
#include "drivers/odometry_bridge/test_trajectory.h"
#include "mbslam/odometry_t.hpp"
#include "test/drivers/process_util.h"

namespace mbslam {
namespace {

using testing_util::BinPath;
using testing_util::ChildProcess;
using testing_util::MakeTempDir;
using testing_util::RunProcess;
using testing_util::WriteTextFile;

int UniqueDomain(int k) { return 20 + (static_cast<int>(getpid()) * 13 + k * 41 + 50) % 200; }

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

std::vector<mbslam::odometry_t> ReadOdometryLog(const std::string& path) {
  std::vector<LcmLogEvent> events;
  EXPECT_TRUE(ReadLcmLog(path, &events, "ODOMETRY").ok());
  std::vector<mbslam::odometry_t> out;
  for (const LcmLogEvent& e : events) {
    mbslam::odometry_t m{};
    EXPECT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
    EXPECT_EQ(e.timestamp, m.utime);
    out.push_back(m);
  }
  return out;
}

void ExpectFieldsExact(const mbslam::odometry_t& got, const OdometrySample& want) {
  EXPECT_EQ(got.utime, want.utime);
  EXPECT_EQ(got.frame_id, want.frame_id);
  EXPECT_EQ(got.child_frame_id, want.child_frame_id);
  const Eigen::Quaterniond& q = want.odom_from_base.rotation;
  const double wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(BitEqual(got.position[i], want.odom_from_base.translation[i])) << i;
    EXPECT_TRUE(BitEqual(got.linear_velocity[i], want.linear_velocity[i])) << i;
    EXPECT_TRUE(BitEqual(got.angular_velocity[i], want.angular_velocity[i])) << i;
  }
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(BitEqual(got.orientation[i], wxyz[i])) << i;
  for (size_t i = 0; i < 36; ++i) {
    EXPECT_TRUE(BitEqual(got.pose_covariance[i], want.pose_covariance[i])) << i;
    EXPECT_TRUE(BitEqual(got.twist_covariance[i], want.twist_covariance[i])) << i;
  }
}

void BridgeRosOdometry(const std::string& transport, int domain, const std::vector<std::string>& wrap) {
  const std::string dir = MakeTempDir("it_dds");
  const std::string log = dir + "/odometry.lcmlog";
  const int count = 50;
  std::vector<std::string> bridge = wrap;
  for (const std::string& a :
       {BinPath("odometry_bridge"), std::string("--quiet"), std::string("--input"), std::string("dds"),
        std::string("--transport"), transport, std::string("--domain"), std::to_string(domain),
        std::string("--topic"), std::string("/robot/odom"), std::string("--reliable"),
        std::string("--max-messages"), std::to_string(count), std::string("--idle-timeout"),
        std::string("20"), std::string("--log"), log}) {
    bridge.push_back(a);
  }
  ChildProcess bridge_process(bridge);
  const auto publisher = RunProcess({BinPath("ros2_odometry_publisher"), "--transport", transport, "--domain",
                                     std::to_string(domain), "--topic", "robot/odom", "--count",
                                     std::to_string(count), "--rate", "200", "--pattern", "fields"},
                                    60.0);
  const auto result = bridge_process.Wait(30.0);
  ASSERT_EQ(publisher.exit_code, kExitOk) << publisher.err;
  ASSERT_EQ(result.exit_code, kExitOk) << result.err;
  const std::vector<mbslam::odometry_t> got = ReadOdometryLog(log);
  ASSERT_EQ(got.size(), static_cast<size_t>(count));
  for (int i = 0; i < count; ++i) {
    EXPECT_EQ(got[static_cast<size_t>(i)].seq, i);
    ExpectFieldsExact(got[static_cast<size_t>(i)], FieldTestOdometry(i));
  }
}

TEST(OdometryBridgeCli, RosOdometryOverSharedMemoryIsBridgedExactly) {
  BridgeRosOdometry("shm", UniqueDomain(1), {});
}

TEST(OdometryBridgeCli, RosOdometryOverUdpInsideAPrivateNetworkNamespace) {
  // Loopback UDP, inside a namespace of its own (only lo exists there).
  const auto probe = RunProcess({"test/netns/run_in_netns.sh", "/bin/true"});
  if (probe.exit_code == 77) GTEST_SKIP() << "network namespaces unavailable: " << probe.err;
  ASSERT_EQ(probe.exit_code, 0) << probe.err;
  // Both processes must share the namespace: one shell runs them there.
  const std::string dir = MakeTempDir("it_udp");
  const std::string log = dir + "/odometry.lcmlog";
  const std::string script = dir + "/inside.sh";
  const int domain = UniqueDomain(2);
  WriteTextFile(script,
                "set -e\n" + BinPath("odometry_bridge") + " --quiet --transport udp --domain " +
                    std::to_string(domain) + " --reliable --max-messages 30 --idle-timeout 20 --log " + log +
                    " &\nb=$!\n" + BinPath("ros2_odometry_publisher") + " --transport udp --domain " +
                    std::to_string(domain) + " --count 30 --rate 200\nwait $b\n");
  const auto r = RunProcess({"test/netns/run_in_netns.sh", "bash", script}, 90.0);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<mbslam::odometry_t> got = ReadOdometryLog(log);
  ASSERT_EQ(got.size(), 30u);
  for (int i = 0; i < 30; ++i) ExpectFieldsExact(got[static_cast<size_t>(i)], FieldTestOdometry(i));
}

TEST(OdometryBridgeCli, FileInputsAndExitCodes) {
  const std::string dir = MakeTempDir("it_files");
  WriteTextFile(dir + "/o.csv", "utime,x,y,z,qx,qy,qz,qw\n100,1,2,3,0,0,0,1\n200,1.5,2,3,0,0,0,1\n");
  auto r = RunProcess({BinPath("odometry_bridge"), "--quiet", "--input", "csv", "--file", dir + "/o.csv",
                       "--log", dir + "/csv.lcmlog"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  std::vector<mbslam::odometry_t> got = ReadOdometryLog(dir + "/csv.lcmlog");
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[1].position[0], 1.5);

  std::vector<TimedPose> poses;
  const ScrewTrajectory screw;
  for (int i = 0; i < 20; ++i) poses.push_back(TimedPose{screw.t0_utime + 50000 * i, screw.At(screw.t0_utime + 50000 * i)});
  ASSERT_TRUE(WriteTumTrajectory(dir + "/o.tum", poses).ok());
  r = RunProcess({BinPath("odometry_bridge"), "--quiet", "--input", "tum", "--file", dir + "/o.tum", "--log",
                  dir + "/tum.lcmlog"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  got = ReadOdometryLog(dir + "/tum.lcmlog");
  ASSERT_EQ(got.size(), 20u);
  EXPECT_NEAR(got[10].linear_velocity[0], screw.twist[0], 1e-5);  // derived from the poses

  r = RunProcess({BinPath("odometry_bridge"), "--quiet", "--input", "csv", "--file", dir + "/missing.csv",
                  "--log", dir + "/x.lcmlog"});
  EXPECT_EQ(r.exit_code, kExitInputNotFound);
  r = RunProcess({BinPath("odometry_bridge"), "--quiet", "--transport", "multicast"});
  EXPECT_EQ(r.exit_code, kExitUsage);
  r = RunProcess({BinPath("odometry_bridge"), "--quiet", "--domain", std::to_string(UniqueDomain(3)),
                  "--idle-timeout", "0.5", "--log", dir + "/none.lcmlog"});
  EXPECT_EQ(r.exit_code, kExitInputTimeout);
  EXPECT_NE(r.err.find("no odometry from ROS 2 nav_msgs::msg::dds_::Odometry_ on rt/odom"), std::string::npos)
      << r.err;
}

TEST(OdometryBridgeCli, SigintStopsALiveBridgeCleanly) {
  const std::string dir = MakeTempDir("it_sigint");
  ChildProcess bridge({BinPath("odometry_bridge"), "--quiet", "--domain", std::to_string(UniqueDomain(4)), "--log",
                       dir + "/o.lcmlog"});
  usleep(500000);
  bridge.Signal(SIGINT);
  const auto r = bridge.Wait(5.0);
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_NE(r.err.find("published 0 odometry messages"), std::string::npos) << r.err;
}

TEST(HandEyeCli, RecoversTheExtrinsicAndWritesItForTheBridge) {
  // A planar robot driving curves; the camera trajectory is up to scale (0.5 m per unit).
  const Rigid3d truth(Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5) *
                          Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX())),
                      Eigen::Vector3d(0.3, 0.1, 0.7));
  std::vector<TimedPose> odometry, camera;
  Rigid3d base;
  for (int i = 0; i < 200; ++i) {
    const int64_t t = 1000000 + 50000 * int64_t{i};
    odometry.push_back(TimedPose{t, base});
    if (i % 2 == 0) {
      Rigid3d cam = base * truth;
      cam.translation *= 2.0;
      camera.push_back(TimedPose{t, cam});
    }
    base = base * Rigid3d::Exp((Vector6d() << 0.05, 0, 0, 0, 0, 0.04 * std::sin(0.05 * i)).finished());
  }
  const std::string dir = MakeTempDir("it_handeye");
  ASSERT_TRUE(WriteTumTrajectory(dir + "/odom.tum", odometry).ok());
  ASSERT_TRUE(WriteTumTrajectory(dir + "/cam.tum", camera).ok());
  auto r = RunProcess({BinPath("handeye_calib"), "--camera", dir + "/cam.tum", "--odometry", dir + "/odom.tum",
                       "--prior-offset", "0.7", "--output", dir + "/extrinsic.yaml", "--verbose"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err << r.out;
  EXPECT_NE(r.out.find("planar motion"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("scale: 0.500000"), std::string::npos) << r.out;
  Rigid3d estimated;
  ASSERT_TRUE(LoadExtrinsicYaml(dir + "/extrinsic.yaml", &estimated).ok());
  EXPECT_LT(RotationDistance(estimated, truth), 1e-6);
  EXPECT_LT(TranslationDistance(estimated, truth), 1e-5);  // TUM files carry ~1e-9 precision
  // The bridge takes the file as its extrinsic.
  r = RunProcess({BinPath("odometry_bridge"), "--extrinsic", dir + "/extrinsic.yaml", "--print-config"});
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  // Straight driving only cannot determine it.
  std::vector<TimedPose> straight_odo, straight_cam;
  for (int i = 0; i < 50; ++i) {
    const Rigid3d b(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.05 * i, 0, 0));
    straight_odo.push_back(TimedPose{1000000 + 50000 * int64_t{i}, b});
    straight_cam.push_back(TimedPose{1000000 + 50000 * int64_t{i}, b * truth});
  }
  ASSERT_TRUE(WriteTumTrajectory(dir + "/so.tum", straight_odo).ok());
  ASSERT_TRUE(WriteTumTrajectory(dir + "/sc.tum", straight_cam).ok());
  r = RunProcess({BinPath("handeye_calib"), "--camera", dir + "/sc.tum", "--odometry", dir + "/so.tum"});
  EXPECT_EQ(r.exit_code, kExitDegenerateData) << r.out << r.err;
  EXPECT_NE(r.err.find("turn"), std::string::npos) << r.err;
  r = RunProcess({BinPath("handeye_calib"), "--camera", dir + "/missing.tum", "--odometry", dir + "/so.tum"});
  EXPECT_EQ(r.exit_code, kExitInputNotFound);
}

}  // namespace
}  // namespace mbslam
