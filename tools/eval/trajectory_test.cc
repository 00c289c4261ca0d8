#include "tools/eval/trajectory.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

namespace mbslam {
namespace eval {
namespace {

TEST(Time, ExactDecimalSeconds) {
  int64_t t = 0;
  ASSERT_TRUE(ParseSecondsToUtime("1341841278.8427", &t));
  EXPECT_EQ(t, 1341841278842700);
  ASSERT_TRUE(ParseSecondsToUtime("1600000000.033333", &t));
  EXPECT_EQ(t, 1600000000033333);
  ASSERT_TRUE(ParseSecondsToUtime("0.0000015", &t));  // rounded at the 7th decimal
  EXPECT_EQ(t, 2);
  ASSERT_TRUE(ParseSecondsToUtime("-0.5", &t));
  EXPECT_EQ(t, -500000);
  ASSERT_TRUE(ParseSecondsToUtime("12", &t));
  EXPECT_EQ(t, 12000000);
  ASSERT_TRUE(ParseSecondsToUtime("1.5e2", &t));
  EXPECT_EQ(t, 150000000);
  EXPECT_FALSE(ParseSecondsToUtime("abc", &t));
  EXPECT_FALSE(ParseSecondsToUtime("", &t));
  EXPECT_EQ(UtimeToSecondsString(1600000000033333), "1600000000.033333");
  EXPECT_EQ(UtimeToSecondsString(-1), "-0.000001");
  for (int64_t v : {int64_t{0}, int64_t{999999}, int64_t{1000000}, int64_t{1234567890123456}}) {
    ASSERT_TRUE(ParseSecondsToUtime(UtimeToSecondsString(v), &t));
    EXPECT_EQ(t, v);
  }
}

TEST(Tum, ParseWriteRoundTrip) {
  const std::string text =
      "# comment\n"
      "1341841279.5107\t-2.4691\t1.0757\t1.0996\t-0.4454\t0.7908\t-0.3627\t0.2114\t\n"
      "\n"
      "1341841278.8427 -2.5508 0.9872 1.1019 -0.4871 0.7673 -0.3519 0.2239\n";
  Trajectory t;
  ASSERT_TRUE(ParseTumTrajectory(text, &t).ok());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[0].utime, 1341841278842700);  // sorted by time
  EXPECT_NEAR(t[0].pose.translation.x(), -2.5508, 1e-12);
  EXPECT_NEAR(
      t[0].pose.rotation.w(),
      0.2239 / std::sqrt(0.4871 * 0.4871 + 0.7673 * 0.7673 + 0.3519 * 0.3519 + 0.2239 * 0.2239),
      1e-12);
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("mbslam_tum_" + std::to_string(::getpid()) + ".tum"))
                               .string();
  ASSERT_TRUE(WriteTumTrajectory(path, t, "test").ok());
  Trajectory back;
  ASSERT_TRUE(ReadTumTrajectory(path, &back).ok());
  ASSERT_EQ(back.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].utime, t[i].utime);
    EXPECT_LT(TranslationDistance(back[i].pose, t[i].pose), 1e-9);
    EXPECT_LT(RotationDistance(back[i].pose, t[i].pose), 1e-8);
  }
  std::filesystem::remove(path);
  EXPECT_FALSE(ParseTumTrajectory("1 2 3\n", &t).ok());
  EXPECT_FALSE(
      ParseTumTrajectory("1 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n", &t).ok());  // duplicate time
  EXPECT_FALSE(ParseTumTrajectory("1 0 0 0 0 0 0 0\n", &t).ok());          // zero quaternion
}

TEST(Association, NearestOneToOneWithinTolerance) {
  Trajectory gt, est;
  for (int i = 0; i < 10; ++i) {
    gt.push_back({i * 100000, Rigid3d()});
  }
  // Estimates 3 ms late, one missing, one far off, two competing for the same truth.
  for (int i : {0, 1, 2, 4, 5, 6, 7, 8}) {
    est.push_back({i * 100000 + 3000, Rigid3d()});
  }
  est.push_back({950000, Rigid3d()});  // 50 ms from 900000 and 1000000: too far
  SortByTime(&est);
  auto pairs = AssociateByTime(est, gt, 20000);
  ASSERT_EQ(pairs.size(), 8u);
  for (const auto& p : pairs) {
    EXPECT_EQ(p.dt_us, 3000);
    EXPECT_EQ(est[p.est].utime - 3000, gt[p.gt].utime);
  }
  Trajectory twins = {{100000, Rigid3d()}, {101000, Rigid3d()}};
  pairs = AssociateByTime(twins, gt, 20000);
  ASSERT_EQ(pairs.size(), 1u);  // one-to-one: the closer estimate wins
  EXPECT_EQ(pairs[0].est, 0u);
  EXPECT_TRUE(AssociateByTime(est, Trajectory(), 20000).empty());
}

TEST(TartanAir, NedToCameraAxes) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("mbslam_tartan_" + std::to_string(::getpid()) + ".txt"))
                               .string();
  {
    FILE* f = std::fopen(path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fprintf(f, "1 2 3 0 0 0 1\n4 5 6 0 0 0 1\n");
    std::fclose(f);
  }
  Trajectory t;
  ASSERT_TRUE(ReadTartanAirPoses(path, 100000, &t).ok());
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[1].utime, 100000);
  EXPECT_LT((t[1].pose.translation - Eigen::Vector3d(4, 5, 6)).norm(), 1e-12);
  // Identity NED body: the camera looks along world x, image right = world y, down = world z.
  const Eigen::Matrix3d R = t[0].pose.RotationMatrix();
  EXPECT_LT((R * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX()).norm(), 1e-12);
  EXPECT_LT((R * Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitY()).norm(), 1e-12);
  EXPECT_LT((R * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 1e-12);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
