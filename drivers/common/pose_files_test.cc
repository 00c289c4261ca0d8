#include "drivers/common/pose_files.h"

#include <gtest/gtest.h>
#include <stdlib.h>

#include <fstream>

#include "common/testing/temp_dir.h"

namespace mbslam {
namespace {

std::string TempDir() { return testing_util::MakeTestTempDir("pose_files"); }

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

TEST(PoseFiles, SecondsAreConvertedExactly) {
  int64_t t = 0;
  ASSERT_TRUE(ParseSecondsToUtime("1305031102.175304", &t).ok());
  EXPECT_EQ(t, 1305031102175304);
  ASSERT_TRUE(ParseSecondsToUtime("1341841278.8427", &t).ok());
  EXPECT_EQ(t, 1341841278842700);
  ASSERT_TRUE(ParseSecondsToUtime("0.0000005", &t).ok());  // half rounds away from zero
  EXPECT_EQ(t, 1);
  ASSERT_TRUE(ParseSecondsToUtime("0.00000049", &t).ok());
  EXPECT_EQ(t, 0);
  ASSERT_TRUE(ParseSecondsToUtime("-1.5", &t).ok());
  EXPECT_EQ(t, -1500000);
  ASSERT_TRUE(ParseSecondsToUtime("12", &t).ok());
  EXPECT_EQ(t, 12000000);
  ASSERT_TRUE(ParseSecondsToUtime("1.000000e-01", &t).ok());  // KITTI times.txt style
  EXPECT_EQ(t, 100000);
  EXPECT_FALSE(ParseSecondsToUtime("abc", &t).ok());
  EXPECT_FALSE(ParseSecondsToUtime("", &t).ok());
  EXPECT_FALSE(ParseSecondsToUtime("1.2.3", &t).ok());
}

TEST(PoseFiles, OtherTimeUnits) {
  int64_t t = 0;
  ASSERT_TRUE(ParseTimeToUtime("1500", "ms", &t).ok());
  EXPECT_EQ(t, 1500000);
  ASSERT_TRUE(ParseTimeToUtime("1.0005", "ms", &t).ok());
  EXPECT_EQ(t, 1001);
  ASSERT_TRUE(ParseTimeToUtime("123456", "us", &t).ok());
  EXPECT_EQ(t, 123456);
  ASSERT_TRUE(ParseTimeToUtime("1317376500123456789", "ns", &t).ok());
  EXPECT_EQ(t, 1317376500123457);
  EXPECT_FALSE(ParseTimeToUtime("1", "h", &t).ok());
  EXPECT_TRUE(IsValidTimeUnit("ns"));
  EXPECT_FALSE(IsValidTimeUnit("min"));
}

TEST(PoseFiles, TumTrajectoryRoundTrip) {
  const std::string dir = TempDir();
  std::vector<TimedPose> poses;
  for (int i = 0; i < 5; ++i) {
    TimedPose p;
    p.utime = 1000000000 + 33333 * i;
    p.pose = Rigid3d::Exp((Vector6d() << 0.1 * i, -0.2, 0.3, 0.01 * i, 0.02, -0.03).finished());
    poses.push_back(p);
  }
  ASSERT_TRUE(WriteTumTrajectory(dir + "/t.tum", poses).ok());
  std::vector<TimedPose> read;
  ASSERT_TRUE(ReadTumTrajectory(dir + "/t.tum", &read).ok());
  ASSERT_EQ(read.size(), poses.size());
  for (size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(read[i].utime, poses[i].utime);
    EXPECT_LT(TranslationDistance(read[i].pose, poses[i].pose), 1e-12);
    EXPECT_LT(RotationDistance(read[i].pose, poses[i].pose), 1e-12);
  }
}

TEST(PoseFiles, TumRejectsBadLines) {
  const std::string dir = TempDir();
  std::vector<TimedPose> poses;
  WriteText(dir + "/a.tum", "# header\n1.0 0 0 0 0 0 0 1\n1.0 0 0 0 0 0 0 1\n");
  EXPECT_FALSE(ReadTumTrajectory(dir + "/a.tum", &poses).ok());  // time does not increase
  WriteText(dir + "/b.tum", "1.0 0 0 0 0 0 0\n");
  EXPECT_FALSE(ReadTumTrajectory(dir + "/b.tum", &poses).ok());  // 7 fields
  WriteText(dir + "/c.tum", "1.0 0 0 0 0 0 0 2\n");
  EXPECT_FALSE(ReadTumTrajectory(dir + "/c.tum", &poses).ok());  // not a unit quaternion
  WriteText(dir + "/d.tum", "1.0 0 0 0 0 0 0 1.0001\n2,1,2,3,0,0,0,1\n");
  ASSERT_TRUE(ReadTumTrajectory(dir + "/d.tum", &poses).ok());  // rounding ok, commas ok
  EXPECT_EQ(poses[1].pose.translation, Eigen::Vector3d(1, 2, 3));
  EXPECT_FALSE(ReadTumTrajectory(dir + "/missing.tum", &poses).ok());
}

TEST(PoseFiles, KittiPoses) {
  const std::string dir = TempDir();
  WriteText(dir + "/k.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n"
            "0 -1 0 1.5 1 0 0 2.5 0 0 1 -3\n");
  std::vector<Rigid3d> poses;
  ASSERT_TRUE(ReadKittiPoses(dir + "/k.txt", &poses).ok());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_EQ(poses[1].translation, Eigen::Vector3d(1.5, 2.5, -3));
  EXPECT_LT((poses[1] * Eigen::Vector3d(1, 0, 0) - Eigen::Vector3d(1.5, 3.5, -3)).norm(), 1e-12);
  WriteText(dir + "/bad.txt", "1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_FALSE(ReadKittiPoses(dir + "/bad.txt", &poses).ok());
  WriteText(dir + "/notrot.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_FALSE(ReadKittiPoses(dir + "/notrot.txt", &poses).ok());
}

TEST(PoseFiles, TartanAirNedPosesBecomeOpticalCameraPoses) {
  const std::string dir = TempDir();
  // Body rotated 90 deg about z (NED down axis): forward now points along world y.
  const double s = std::sqrt(0.5);
  WriteText(dir + "/pose_left.txt", "1 2 3 0 0 " + std::to_string(s) + " " + std::to_string(s) + "\n");
  std::vector<Rigid3d> poses;
  ASSERT_TRUE(ReadTartanAirPoses(dir + "/pose_left.txt", &poses).ok());
  ASSERT_EQ(poses.size(), 1u);
  const Eigen::Matrix3d r = poses[0].RotationMatrix();
  // Optical z (viewing direction) = body forward = world +y; optical x (right) = body
  // y = world -x; optical y (down) = body z = world z.
  EXPECT_LT((r.col(2) - Eigen::Vector3d(0, 1, 0)).norm(), 1e-6);
  EXPECT_LT((r.col(0) - Eigen::Vector3d(-1, 0, 0)).norm(), 1e-6);
  EXPECT_LT((r.col(1) - Eigen::Vector3d(0, 0, 1)).norm(), 1e-6);
  EXPECT_EQ(poses[0].translation, Eigen::Vector3d(1, 2, 3));
}

TEST(PoseFiles, SplitFields) {
  EXPECT_EQ(SplitFields(" a\tb,,c  "), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_TRUE(SplitFields("   ").empty());
}

}  // namespace
}  // namespace mbslam
