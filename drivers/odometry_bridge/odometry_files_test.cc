#include "drivers/odometry_bridge/odometry_files.h"

#include <gtest/gtest.h>

#include <sstream>

#include "drivers/common/pose_files.h"
#include "drivers/common/test_util.h"
#include "drivers/odometry_bridge/test_trajectory.h"

namespace mbslam {
namespace {

using testing_util::MakeTempDir;
using testing_util::WriteTextFile;

TEST(OdometryCsv, HeaderWithUtimeAndTwist) {
  const std::string dir = MakeTempDir("csv");
  WriteTextFile(dir + "/o.csv",
                "utime,x,y,z,qx,qy,qz,qw,vx,wz,frame_id,child_frame_id\n"
                "1000,1,2,3,0,0,0,1,0.5,0.1,odom,base_link\n"
                "2000,1.5,2,3,0,0,0.0499792,0.99875,0.5,0.1,odom,base_link\n");
  std::vector<OdometrySample> s;
  ASSERT_TRUE(ReadOdometryCsv(dir + "/o.csv", &s).ok());
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[1].utime, 2000);
  EXPECT_EQ(s[1].seq, 1);
  EXPECT_EQ(s[1].odom_from_base.translation.x(), 1.5);
  EXPECT_EQ(s[0].linear_velocity.x(), 0.5);
  EXPECT_EQ(s[0].angular_velocity.z(), 0.1);
  EXPECT_EQ(s[0].pose_covariance[0], -1.0);
}

TEST(OdometryCsv, SecondsAndRosStyleNames) {
  const std::string dir = MakeTempDir("csv2");
  WriteTextFile(dir + "/a.csv", "t,x,y,z,qx,qy,qz,qw\n1305031102.175304,0,0,0,0,0,0,1\n");
  std::vector<OdometrySample> s;
  ASSERT_TRUE(ReadOdometryCsv(dir + "/a.csv", &s).ok());
  EXPECT_EQ(s[0].utime, 1305031102175304);
  WriteTextFile(dir + "/b.csv",
                "header.stamp.sec,header.stamp.nanosec,pose.pose.position.x,pose.pose.position.y,"
                "pose.pose.position.z,pose.pose.orientation.x,pose.pose.orientation.y,"
                "pose.pose.orientation.z,pose.pose.orientation.w,twist.twist.angular.z\n"
                "12,500000000,1,2,3,0,0,0,1,0.25\n");
  ASSERT_TRUE(ReadOdometryCsv(dir + "/b.csv", &s).ok());
  EXPECT_EQ(s[0].utime, 12500000);
  EXPECT_EQ(s[0].angular_velocity.z(), 0.25);
}

TEST(OdometryCsv, Ros2EchoRowsWithoutHeader) {
  const OdometrySample ref = FieldTestOdometry(3);
  std::ostringstream row;
  row.precision(17);
  const int64_t sec = ref.utime / 1000000, usec = ref.utime % 1000000;
  row << sec << "," << usec * 1000 << "," << ref.frame_id << "," << ref.child_frame_id;
  const Eigen::Quaterniond& q = ref.odom_from_base.rotation;
  for (double v : {ref.odom_from_base.translation.x(), ref.odom_from_base.translation.y(),
                   ref.odom_from_base.translation.z(), q.x(), q.y(), q.z(), q.w()}) {
    row << "," << v;
  }
  for (double v : ref.pose_covariance) row << "," << v;
  for (int i = 0; i < 3; ++i) row << "," << ref.linear_velocity[i];
  for (int i = 0; i < 3; ++i) row << "," << ref.angular_velocity[i];
  for (double v : ref.twist_covariance) row << "," << v;
  const std::string dir = MakeTempDir("csv3");
  WriteTextFile(dir + "/echo.csv", row.str() + "\n");
  std::vector<OdometrySample> s;
  ASSERT_TRUE(ReadOdometryCsv(dir + "/echo.csv", &s).ok());
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].utime, ref.utime);
  EXPECT_EQ(s[0].child_frame_id, "base_footprint");
  EXPECT_EQ(s[0].odom_from_base.translation, ref.odom_from_base.translation);  // 17 digits: exact
  EXPECT_EQ(s[0].pose_covariance, ref.pose_covariance);
  EXPECT_EQ(s[0].twist_covariance, ref.twist_covariance);
  EXPECT_EQ(s[0].angular_velocity, ref.angular_velocity);
}

TEST(OdometryCsv, BadFilesAreErrors) {
  const std::string dir = MakeTempDir("csv4");
  std::vector<OdometrySample> s;
  EXPECT_FALSE(ReadOdometryCsv(dir + "/missing.csv", &s).ok());
  for (const std::string& text :
       {std::string("x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,1\n"),                 // no time column
        std::string("utime,x,y,z,qx,qy,qz\n1,0,0,0,0,0,0\n"),               // no qw
        std::string("utime,x,y,z,qx,qy,qz,qw\n1,0,0,0,0,0,0,0\n"),          // zero quaternion
        std::string("utime,x,y,z,qx,qy,qz,qw\n2,0,0,0,0,0,0,1\n1,0,0,0,0,0,0,1\n"),  // backwards
        std::string("utime,x,y,z,qx,qy,qz,qw\n1,a,0,0,0,0,0,1\n"),          // not a number
        std::string("1,2,3\n"),                                              // headerless, wrong width
        std::string("utime,x,y,z,qx,qy,qz,qw\n")}) {                         // no samples
    WriteTextFile(dir + "/bad.csv", text);
    EXPECT_FALSE(ReadOdometryCsv(dir + "/bad.csv", &s).ok()) << text;
  }
}

TEST(OdometryTum, PosesWithDerivedTwists) {
  const ScrewTrajectory screw;
  std::vector<TimedPose> poses;
  for (int i = 0; i < 10; ++i) {
    const int64_t t = screw.t0_utime + 20000 * i;
    poses.push_back(TimedPose{t, screw.At(t)});
  }
  const std::string dir = MakeTempDir("tumodo");
  ASSERT_TRUE(WriteTumTrajectory(dir + "/o.tum", poses).ok());
  std::vector<OdometrySample> s;
  ASSERT_TRUE(ReadOdometryTum(dir + "/o.tum", true, &s).ok());
  ASSERT_EQ(s.size(), 10u);
  for (const OdometrySample& x : s) {
    EXPECT_LT((x.linear_velocity - screw.twist.head<3>()).norm(), 1e-6);
    EXPECT_LT((x.angular_velocity - screw.twist.tail<3>()).norm(), 1e-6);
    EXPECT_EQ(x.twist_covariance[0], -1.0);
  }
  ASSERT_TRUE(ReadOdometryTum(dir + "/o.tum", false, &s).ok());
  EXPECT_EQ(s[3].linear_velocity, Eigen::Vector3d::Zero());
}

// Regression (issue 9): with a repeated column name the header's last index pointed
// past the end of a shorter row (heap overread); ROS stamps out of int64 range were a
// double -> int64 overflow; twists derived from poses far apart in space but not in
// time were infinite and passed on.
TEST(OdometryFiles, MalformedColumnsStampsAndTwistsAreErrors) {
  const std::string dir = MakeTempDir("odo_range");
  std::vector<OdometrySample> s;
  for (const std::string& text :
       {std::string("x,x,y,z,qx,qy,qz,qw,utime\n0,0,0,0,0,0,0,1\n"),
        std::string("sec,nanosec,x,y,z,qx,qy,qz,qw\n1e300,0,0,0,0,0,0,0,1\n"),
        std::string("sec,nanosec,x,y,z,qx,qy,qz,qw\n1,-5,0,0,0,0,0,0,1\n")}) {
    WriteTextFile(dir + "/bad.csv", text);
    EXPECT_FALSE(ReadOdometryCsv(dir + "/bad.csv", &s).ok()) << text;
  }
  std::string echo = "1e300,0,odom,base_link,1,2,0,0,0,0,1";
  for (int i = 0; i < 36 + 6 + 36; ++i) echo += ",0";
  WriteTextFile(dir + "/echo.csv", echo + "\n");
  EXPECT_FALSE(ReadOdometryCsv(dir + "/echo.csv", &s).ok());

  WriteTextFile(dir + "/far.tum", "1.000000 0 0 0 0 0 0 1\n1.000001 1e305 0 0 0 0 0 1\n");
  EXPECT_TRUE(ReadOdometryTum(dir + "/far.tum", false, &s).ok());
  EXPECT_FALSE(ReadOdometryTum(dir + "/far.tum", true, &s).ok());
  WriteTextFile(dir + "/span.tum", "-9000000000000 0 0 0 0 0 0 1\n9000000000000 1 0 0 0 0 0 1\n");
  ASSERT_TRUE(ReadOdometryTum(dir + "/span.tum", true, &s).ok());
  EXPECT_GT(s[1].linear_velocity.x(), 0.0);
}

}  // namespace
}  // namespace mbslam
