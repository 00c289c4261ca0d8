// Fast DDS in process, shared memory (and loopback UDP), one domain per test.

#include "drivers/odometry_bridge/dds_odometry.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>

#include "common/util/time.h"
#include "drivers/odometry_bridge/ros2_odometry_conversion.h"
#include "drivers/odometry_bridge/test_trajectory.h"

namespace mbslam {
namespace {

// A domain id no other test process uses at the same time (0-232).
int UniqueDomain(int k) { return 20 + (static_cast<int>(getpid()) * 7 + k * 31) % 200; }

bool BitEqual(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void ExpectExactlyEqual(const OdometrySample& got, const OdometrySample& want) {
  EXPECT_EQ(got.utime, want.utime);
  EXPECT_EQ(got.frame_id, want.frame_id);
  EXPECT_EQ(got.child_frame_id, want.child_frame_id);
  for (int i = 0; i < 3; ++i) {
    EXPECT_TRUE(BitEqual(got.odom_from_base.translation[i], want.odom_from_base.translation[i]));
    EXPECT_TRUE(BitEqual(got.linear_velocity[i], want.linear_velocity[i]));
    EXPECT_TRUE(BitEqual(got.angular_velocity[i], want.angular_velocity[i]));
  }
  for (int i = 0; i < 4; ++i) {
    EXPECT_TRUE(BitEqual(got.odom_from_base.rotation.coeffs()[i], want.odom_from_base.rotation.coeffs()[i]));
  }
  for (size_t i = 0; i < 36; ++i) {
    EXPECT_TRUE(BitEqual(got.pose_covariance[i], want.pose_covariance[i])) << i;
    EXPECT_TRUE(BitEqual(got.twist_covariance[i], want.twist_covariance[i])) << i;
  }
}

TEST(Ros2Odometry, TopicNamesAndStamps) {
  EXPECT_EQ(Ros2TopicToDds("odom"), "rt/odom");
  EXPECT_EQ(Ros2TopicToDds("/robot/odom"), "rt/robot/odom");
  EXPECT_EQ(Ros2TopicToDds("rt/odom"), "rt/odom");
  EXPECT_EQ(Ros2StampToUtime(1700000000, 123456789), 1700000000123457);  // rounded
  EXPECT_EQ(Ros2StampToUtime(5, 499), 5000000);
  int32_t sec = 0;
  uint32_t nanosec = 0;
  UtimeToRos2Stamp(1700000000123457, &sec, &nanosec);
  EXPECT_EQ(sec, 1700000000);
  EXPECT_EQ(nanosec, 123457000u);
  UtimeToRos2Stamp(-1, &sec, &nanosec);
  EXPECT_EQ(sec, -1);
  EXPECT_EQ(nanosec, 999999000u);
  EXPECT_EQ(Ros2StampToUtime(sec, nanosec), -1);
}

TEST(Ros2Odometry, GeneratedTypeFieldsMapOneToOne) {
  nav_msgs::msg::dds_::Odometry_ msg;
  msg.header_().stamp_().sec_(12);
  msg.header_().stamp_().nanosec_(345000);
  msg.header_().frame_id_("map");
  msg.child_frame_id_("base_link");
  msg.pose_().pose_().position_().x_(1.5);
  msg.pose_().pose_().orientation_().z_(std::sqrt(0.5));
  msg.pose_().pose_().orientation_().w_(std::sqrt(0.5));
  msg.pose_().covariance_()[7] = 0.25;   // row 1, column 1: var(y)
  msg.twist_().twist_().linear_().x_(0.7);
  msg.twist_().twist_().angular_().z_(-0.2);
  msg.twist_().covariance_()[35] = 0.01;  // var(wz)
  OdometrySample s;
  bool renormalised = true;
  ASSERT_TRUE(FromRos2Odometry(msg, &s, &renormalised).ok());
  EXPECT_FALSE(renormalised);
  EXPECT_EQ(s.utime, 12000345);
  EXPECT_EQ(s.frame_id, "map");
  EXPECT_EQ(s.child_frame_id, "base_link");
  EXPECT_EQ(s.odom_from_base.translation.x(), 1.5);
  EXPECT_EQ(s.odom_from_base.rotation.w(), std::sqrt(0.5));
  EXPECT_EQ(s.odom_from_base.rotation.z(), std::sqrt(0.5));
  EXPECT_EQ(s.pose_covariance[7], 0.25);
  EXPECT_EQ(s.twist_covariance[35], 0.01);
  EXPECT_EQ(s.linear_velocity.x(), 0.7);
  EXPECT_EQ(s.angular_velocity.z(), -0.2);
  nav_msgs::msg::dds_::Odometry_ back;
  ToRos2Odometry(s, &back);
  EXPECT_TRUE(back == msg);
  msg.pose_().pose_().orientation_().w_(0.0);
  msg.pose_().pose_().orientation_().z_(0.0);
  EXPECT_FALSE(FromRos2Odometry(msg, &s, &renormalised).ok());
}

void RunWriterReader(const DdsOptions& options, int count) {
  Status st;
  std::unique_ptr<DdsOdometryReader> reader = DdsOdometryReader::Create(options, &st);
  ASSERT_TRUE(reader) << st.message();
  std::unique_ptr<DdsOdometryWriter> writer = DdsOdometryWriter::Create(options, &st);
  ASSERT_TRUE(writer) << st.message();
  ASSERT_TRUE(writer->WaitForReaders(1, 10 * kUsecPerSec)) << "no match on " << options.transport;
  for (int i = 0; i < count; ++i) ASSERT_TRUE(writer->Write(FieldTestOdometry(i)).ok());
  EXPECT_TRUE(writer->WaitForAcknowledgments(5 * kUsecPerSec));
  for (int i = 0; i < count; ++i) {
    OdometrySample s;
    ASSERT_TRUE(reader->Pop(&s, 5 * kUsecPerSec)) << "message " << i << " missing";
    EXPECT_EQ(s.seq, i);
    ExpectExactlyEqual(s, FieldTestOdometry(i));
  }
  EXPECT_EQ(reader->received(), count);
  EXPECT_EQ(reader->rejected(), 0);
  EXPECT_EQ(reader->matched_writers(), 1);
}

TEST(DdsOdometry, SharedMemoryDeliversExactFields) {
  DdsOptions options;
  options.domain_id = UniqueDomain(1);
  options.reliable = true;
  RunWriterReader(options, 40);
}

TEST(DdsOdometry, LoopbackUdpDeliversExactFields) {
  DdsOptions options;
  options.domain_id = UniqueDomain(2);
  options.transport = "udp";
  options.reliable = true;
  RunWriterReader(options, 20);
}

TEST(DdsOdometry, InvalidMessagesAreCountedNotDelivered) {
  DdsOptions options;
  options.domain_id = UniqueDomain(3);
  options.reliable = true;
  Status st;
  auto reader = DdsOdometryReader::Create(options, &st);
  ASSERT_TRUE(reader) << st.message();
  auto writer = DdsOdometryWriter::Create(options, &st);
  ASSERT_TRUE(writer) << st.message();
  ASSERT_TRUE(writer->WaitForReaders(1, 10 * kUsecPerSec));
  OdometrySample bad = FieldTestOdometry(0);
  bad.odom_from_base.rotation.coeffs().setZero();  // "orientation unknown"
  ASSERT_TRUE(writer->Write(bad).ok());
  ASSERT_TRUE(writer->Write(FieldTestOdometry(1)).ok());
  EXPECT_TRUE(writer->WaitForAcknowledgments(5 * kUsecPerSec));
  OdometrySample s;
  ASSERT_TRUE(reader->Pop(&s, 5 * kUsecPerSec));
  EXPECT_EQ(s.utime, FieldTestOdometry(1).utime);
  EXPECT_EQ(reader->rejected(), 1);
  EXPECT_NE(reader->last_rejection().find("norm"), std::string::npos);
  EXPECT_FALSE(reader->Pop(&s, 100000));
}

TEST(DdsOdometry, BestEffortReaderMatchesAReliableWriter) {
  DdsOptions options;
  options.domain_id = UniqueDomain(4);
  Status st;
  auto reader = DdsOdometryReader::Create(options, &st);  // best effort (default)
  ASSERT_TRUE(reader) << st.message();
  auto writer = DdsOdometryWriter::Create(options, &st);  // reliable
  ASSERT_TRUE(writer) << st.message();
  ASSERT_TRUE(writer->WaitForReaders(1, 10 * kUsecPerSec));
  // Best effort may lose a sample: the writer can match the reader before the
  // reader has matched the writer (discovery is asymmetric), and nothing is
  // resent. So the writer repeats until one arrives; what arrives is exact.
  OdometrySample s;
  bool got = false;
  for (int attempt = 0; attempt < 50 && !got; ++attempt) {
    ASSERT_TRUE(writer->Write(FieldTestOdometry(5)).ok());
    got = reader->Pop(&s, 200000);
  }
  ASSERT_TRUE(got);
  ExpectExactlyEqual(s, FieldTestOdometry(5));
}

TEST(DdsOdometry, BadOptionsAreErrors) {
  DdsOptions options;
  options.transport = "multicast";
  Status st;
  EXPECT_FALSE(DdsOdometryReader::Create(options, &st));
  EXPECT_FALSE(st.ok());
  options = DdsOptions();
  options.transport = "udp";
  options.initial_peers = {"not-an-address"};
  EXPECT_FALSE(DdsOdometryReader::Create(options, &st));
}

}  // namespace
}  // namespace mbslam
