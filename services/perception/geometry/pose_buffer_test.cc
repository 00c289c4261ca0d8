#include "services/perception/geometry/pose_buffer.h"

#include <gtest/gtest.h>

#include <limits>

namespace mbslam {
namespace {

// A trajectory with a constant twist: T(t) = Exp(t xi) * T0. Geodesic interpolation
// is exact on it, so the error must be at rounding level.
Rigid3d TrueTrajectory(double t) {
  Vector6d xi;
  xi << 0.8, -0.1, 0.05, 0.02, 0.3, -0.05;
  const Rigid3d t0(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())),
                   Eigen::Vector3d(1.0, 2.0, 0.0));
  return Rigid3d::Exp(t * xi) * t0;
}

TEST(PoseBuffer, InterpolationOnKnownTrajectoryIsExact) {
  PoseBuffer buffer;
  for (int i = 0; i <= 100; ++i) {
    const int64_t utime = 1000000 + i * 20000;  // 50 Hz
    ASSERT_TRUE(buffer.Insert(utime, TrueTrajectory((utime - 1000000) * 1e-6)).ok());
  }
  double max_err = 0.0;
  for (int64_t utime = 1000000; utime <= 3000000; utime += 3331) {
    Rigid3d pose;
    ASSERT_EQ(buffer.Interpolate(utime, &pose), InterpolationResult::kOk);
    const Rigid3d truth = TrueTrajectory((utime - 1000000) * 1e-6);
    max_err = std::max(max_err, TranslationDistance(pose, truth));
    EXPECT_LT(RotationDistance(pose, truth), 1e-9);
  }
  EXPECT_LT(max_err, 1e-9);
}

TEST(PoseBuffer, ExtrapolationContinuesAConstantTwist) {
  PoseBuffer buffer;
  for (int i = 0; i <= 10; ++i) ASSERT_TRUE(buffer.Insert(i * 20000, TrueTrajectory(i * 0.02)).ok());
  Rigid3d pose;
  ASSERT_TRUE(buffer.Extrapolate(230000, &pose));
  EXPECT_LT(TranslationDistance(pose, TrueTrajectory(0.23)), 1e-9);
  EXPECT_FALSE(buffer.Extrapolate(100000, &pose));
}

TEST(PoseBuffer, ReportsOutOfRangeAndGaps) {
  PoseBuffer buffer(/*max_gap_us=*/100000);
  Rigid3d pose;
  EXPECT_EQ(buffer.Interpolate(5, &pose), InterpolationResult::kEmpty);
  ASSERT_TRUE(buffer.Insert(1000, Rigid3d()).ok());
  ASSERT_TRUE(buffer.Insert(2000, Rigid3d()).ok());
  ASSERT_TRUE(buffer.Insert(500000, Rigid3d()).ok());
  EXPECT_EQ(buffer.Interpolate(999, &pose), InterpolationResult::kBeforeFirst);
  EXPECT_EQ(buffer.Interpolate(500001, &pose), InterpolationResult::kAfterLast);
  EXPECT_EQ(buffer.Interpolate(1500, &pose), InterpolationResult::kOk);
  EXPECT_EQ(buffer.Interpolate(300000, &pose), InterpolationResult::kGapTooLarge);
}

TEST(PoseBuffer, RejectsTimeGoingBackAndNonFinite) {
  PoseBuffer buffer;
  ASSERT_TRUE(buffer.Insert(1000, Rigid3d()).ok());
  EXPECT_FALSE(buffer.Insert(1000, Rigid3d()).ok());
  EXPECT_FALSE(buffer.Insert(900, Rigid3d()).ok());
  Rigid3d bad;
  bad.translation.x() = std::nan("");
  EXPECT_FALSE(buffer.Insert(2000, bad).ok());
  EXPECT_EQ(buffer.size(), 1u);
  buffer.Insert(3000, Rigid3d());
  buffer.Insert(4000, Rigid3d());
  buffer.PruneBefore(3500);
  EXPECT_EQ(buffer.first_utime(), 3000);
}

// Regression (issue 9, a TUM groundtruth.txt with times -9e12 s and 9e12 s): the gap
// b.utime - a.utime overflowed int64 (UBSan: signed integer overflow). The span between
// two samples is now exact over the whole int64 range.
TEST(PoseBuffer, SamplesAtTheEndsOfTheTimeRange) {
  const int64_t max = std::numeric_limits<int64_t>::max();
  const Rigid3d moved(Eigen::Quaterniond::Identity(), Eigen::Vector3d(2, 0, 0));
  Rigid3d pose;
  // 1.8e19 us apart: more than any int64 gap bound.
  PoseBuffer wide(/*max_gap_us=*/max);
  ASSERT_TRUE(wide.Insert(-9000000000000000000, Rigid3d()).ok());
  ASSERT_TRUE(wide.Insert(9000000000000000000, moved).ok());
  EXPECT_EQ(wide.Interpolate(0, &pose), InterpolationResult::kGapTooLarge);
  ASSERT_TRUE(wide.Extrapolate(9000000000000000000, &pose));
  EXPECT_NEAR(pose.translation.x(), 2.0, 1e-9);
  // 8e18 us apart, within the bound: interpolated.
  PoseBuffer half(/*max_gap_us=*/max);
  ASSERT_TRUE(half.Insert(-4000000000000000000, Rigid3d()).ok());
  ASSERT_TRUE(half.Insert(4000000000000000000, moved).ok());
  ASSERT_EQ(half.Interpolate(0, &pose), InterpolationResult::kOk);
  EXPECT_NEAR(pose.translation.x(), 1.0, 1e-9);
}

}  // namespace
}  // namespace mbslam
