#include "drivers/odometry_bridge/odometry_sample.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

#include "drivers/common/test_util.h"
#include "drivers/odometry_bridge/odometry_bridge_options.h"
#include "drivers/odometry_bridge/test_trajectory.h"
#include "mbslam/pose_t.hpp"

namespace mbslam {
namespace {

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

TEST(OdometryQuaternion, UnitQuaternionsPassBitExact) {
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.3, -0.1, 0.7, 0.2).normalized();
  Eigen::Quaterniond out;
  bool renormalised = true;
  ASSERT_TRUE(OdometryQuaternion(q.x(), q.y(), q.z(), q.w(), &out, &renormalised).ok());
  EXPECT_FALSE(renormalised);
  EXPECT_TRUE(BitEqual(out.w(), q.w()));
  EXPECT_TRUE(BitEqual(out.x(), q.x()));
  EXPECT_TRUE(BitEqual(out.z(), q.z()));
}

TEST(OdometryQuaternion, SlightlyOffIsNormalisedGarbageIsRejected) {
  Eigen::Quaterniond out;
  bool renormalised = false;
  ASSERT_TRUE(OdometryQuaternion(0, 0, 0, 1.005, &out, &renormalised).ok());
  EXPECT_TRUE(renormalised);
  EXPECT_DOUBLE_EQ(out.w(), 1.0);
  EXPECT_FALSE(OdometryQuaternion(0, 0, 0, 0, &out, &renormalised).ok());  // "unknown" as some drivers send
  EXPECT_FALSE(OdometryQuaternion(0, 0, 0, 2, &out, &renormalised).ok());
  EXPECT_FALSE(OdometryQuaternion(NAN, 0, 0, 1, &out, &renormalised).ok());
}

TEST(OdometrySample, MessageRoundTripIsExactAndWxyz) {
  const OdometrySample s = FieldTestOdometry(17);
  mbslam::odometry_t msg{};
  ToOdometryMessage(s, &msg);
  EXPECT_EQ(msg.utime, s.utime);
  EXPECT_EQ(msg.frame_id, "odom");
  EXPECT_EQ(msg.child_frame_id, "base_footprint");
  EXPECT_TRUE(BitEqual(msg.orientation[0], s.odom_from_base.rotation.w()));
  EXPECT_TRUE(BitEqual(msg.orientation[3], s.odom_from_base.rotation.z()));
  EXPECT_TRUE(BitEqual(msg.pose_covariance[35], s.pose_covariance[35]));
  EXPECT_TRUE(BitEqual(msg.angular_velocity[2], s.angular_velocity.z()));
  OdometrySample back;
  ASSERT_TRUE(FromOdometryMessage(msg, &back).ok());
  EXPECT_EQ(back.odom_from_base.translation, s.odom_from_base.translation);
  EXPECT_TRUE(BitEqual(back.odom_from_base.rotation.x(), s.odom_from_base.rotation.x()));
  EXPECT_EQ(back.twist_covariance, s.twist_covariance);
  msg.position[1] = NAN;
  EXPECT_FALSE(FromOdometryMessage(msg, &back).ok());
}

TEST(OdometrySample, ValidationAndUnknownCovariance) {
  OdometrySample s;
  EXPECT_EQ(s.pose_covariance[0], -1.0);  // unknown by default
  EXPECT_TRUE(ValidateOdometrySample(s).ok());
  s.linear_velocity.x() = INFINITY;
  EXPECT_FALSE(ValidateOdometrySample(s).ok());
  s = OdometrySample();
  s.twist_covariance[7] = NAN;
  EXPECT_FALSE(ValidateOdometrySample(s).ok());
}

TEST(OdometrySample, TwistFromPosesRecoversAConstantBodyTwist) {
  const ScrewTrajectory screw;
  Eigen::Vector3d v, w;
  TwistFromPoses(screw.At(screw.t0_utime + 100000), screw.At(screw.t0_utime + 120000), 0.02, &v, &w);
  EXPECT_LT((v - screw.twist.head<3>()).norm(), 1e-9);
  EXPECT_LT((w - screw.twist.tail<3>()).norm(), 1e-9);
  TwistFromPoses(Rigid3d(), Rigid3d(), 0.0, &v, &w);
  EXPECT_EQ(v, Eigen::Vector3d::Zero());
}

TEST(Extrinsic, DefaultLooksForwardFromAnXForwardZUpBase) {
  ExtrinsicOptions options;
  ASSERT_TRUE(options.Check());
  Rigid3d base_from_cam;
  ASSERT_TRUE(options.Resolve(&base_from_cam).ok());
  const Eigen::Matrix3d r = base_from_cam.RotationMatrix();
  EXPECT_LT((r * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 1e-12);   // optical axis forward
  EXPECT_LT((r * Eigen::Vector3d::UnitX() + Eigen::Vector3d::UnitY()).norm(), 1e-12);   // image right = base -y
  EXPECT_LT((r * Eigen::Vector3d::UnitY() + Eigen::Vector3d::UnitZ()).norm(), 1e-12);   // image down = base -z
  options.rotation_wxyz = {1, 1, 0, 0};
  EXPECT_FALSE(options.Check());
}

TEST(Extrinsic, YamlRoundTripAndSimulatorLayout) {
  const std::string dir = testing_util::MakeTempDir("extr");
  const Rigid3d x(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized())),
                  Eigen::Vector3d(0.2, -0.1, 0.5));
  testing_util::WriteTextFile(dir + "/a.yaml", ExtrinsicToYaml(x, "test\nsecond line"));
  Rigid3d read;
  ASSERT_TRUE(LoadExtrinsicYaml(dir + "/a.yaml", &read).ok());
  EXPECT_LT(TranslationDistance(read, x), 1e-10);
  EXPECT_LT(RotationDistance(read, x), 1e-10);
  testing_util::WriteTextFile(dir + "/sim.yaml", "translation: [0.1, 0, 1.2]\nquaternion: [1, 0, 0, 0]\n");
  ASSERT_TRUE(LoadExtrinsicYaml(dir + "/sim.yaml", &read).ok());
  EXPECT_EQ(read.translation.z(), 1.2);
  ExtrinsicOptions options;
  options.file = dir + "/sim.yaml";
  ASSERT_TRUE(options.Resolve(&read).ok());
  EXPECT_EQ(read.translation.x(), 0.1);
  testing_util::WriteTextFile(dir + "/bad.yaml", "translation: [0.1, 0]\nquaternion: [1, 0, 0, 0]\n");
  EXPECT_FALSE(LoadExtrinsicYaml(dir + "/bad.yaml", &read).ok());
  EXPECT_FALSE(LoadExtrinsicYaml(dir + "/missing.yaml", &read).ok());
}

// The LCM pose input (odometry_bridge --input lcm), moved out of the bridge's handler so
// that it can be tested and fuzzed. Regression (issue 9): the twist's time step was
// utime - previous utime in int64, undefined for times of opposite sign near the ends.
TEST(OdometryFromPoseMessage, DecodesDerivesTwistsAndSurvivesExtremeTimes) {
  auto encode = [](int64_t utime, double x, double w) {
    mbslam::pose_t p{};
    p.utime = utime;
    p.target_frame = "odom";
    p.source_frame = "base_link";
    p.position[0] = x;
    p.orientation[0] = w;
    std::vector<uint8_t> b(static_cast<size_t>(p.getEncodedSize()));
    p.encode(b.data(), 0, static_cast<int>(b.size()));
    return b;
  };
  OdometrySample a, b;
  std::vector<uint8_t> m = encode(1000000, 0.0, 1.0);
  ASSERT_TRUE(OdometryFromPoseMessage(m.data(), m.size(), nullptr, true, &a).ok());
  EXPECT_EQ(a.frame_id, "odom");
  m = encode(1100000, 0.1, 1.0);
  ASSERT_TRUE(OdometryFromPoseMessage(m.data(), m.size(), &a, true, &b).ok());
  EXPECT_NEAR(b.linear_velocity.x(), 1.0, 1e-9);
  EXPECT_EQ(b.seq, 1);

  m = encode(std::numeric_limits<int64_t>::min() + 1, 0.0, 1.0);
  ASSERT_TRUE(OdometryFromPoseMessage(m.data(), m.size(), nullptr, true, &a).ok());
  m = encode(std::numeric_limits<int64_t>::max(), 1.0, 1.0);
  ASSERT_TRUE(OdometryFromPoseMessage(m.data(), m.size(), &a, true, &b).ok());
  EXPECT_TRUE(ValidateOdometrySample(b).ok());

  m = encode(5, 0.0, 0.0);  // zero quaternion
  EXPECT_FALSE(OdometryFromPoseMessage(m.data(), m.size(), nullptr, true, &a).ok());
  EXPECT_FALSE(OdometryFromPoseMessage(m.data(), m.size() - 3, nullptr, true, &a).ok());
}

}  // namespace
}  // namespace mbslam
