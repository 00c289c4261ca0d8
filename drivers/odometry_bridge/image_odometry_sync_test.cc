#include "drivers/odometry_bridge/image_odometry_sync.h"

#include <gtest/gtest.h>

#include "common/util/time.h"
#include "drivers/odometry_bridge/test_trajectory.h"

namespace mbslam {
namespace {

const Rigid3d kBaseFromCam(Eigen::Quaterniond(0.5, -0.5, 0.5, -0.5), Eigen::Vector3d(0.3, 0.05, 0.8));

// Odometry at 50 Hz for 2 s along a screw motion; images at 30 Hz from 0.1 s before
// to 0.1 s after it. The camera pose at an image time is known in closed form.
TEST(ImageOdometrySync, InterpolationOnAKnownTrajectoryIsExact) {
  const ScrewTrajectory screw;
  ImageOdometrySync sync(kBaseFromCam, 100000, 10 * kUsecPerSec, 1000);
  std::vector<ImageOdometry> results;
  std::vector<ImageStamp> images;
  for (int i = 0;; ++i) {
    const int64_t t = screw.t0_utime - 100000 + (i * 1000000) / 30;
    if (t > screw.t0_utime + 2100000) break;
    images.push_back(ImageStamp{t, i, "cam"});
  }
  // Interleave as a live system would: each image arrives with the odometry of its time.
  size_t next_image = 0;
  for (int k = 0; k <= 100; ++k) {
    const int64_t t = screw.t0_utime + 20000 * k;
    while (next_image < images.size() && images[next_image].utime <= t + 5000) {
      sync.AddImage(images[next_image++], &results);
    }
    sync.AddOdometry(screw.Sample(t, k), &results);
  }
  while (next_image < images.size()) sync.AddImage(images[next_image++], &results);
  sync.Flush(&results);
  ASSERT_EQ(results.size(), images.size());
  double worst_m = 0.0, worst_rad = 0.0;
  int ok = 0;
  for (const ImageOdometry& r : results) {
    const int64_t t = r.image.utime;
    if (t < screw.t0_utime) {
      EXPECT_EQ(r.result, InterpolationResult::kBeforeFirst) << t;
      continue;
    }
    if (t > screw.t0_utime + 2000000) {
      EXPECT_EQ(r.result, InterpolationResult::kAfterLast) << t;
      EXPECT_NE(r.detail.find("odometry covers"), std::string::npos);
      continue;
    }
    ASSERT_EQ(r.result, InterpolationResult::kOk) << t;
    ++ok;
    const Rigid3d truth = screw.At(t) * kBaseFromCam;
    worst_m = std::max(worst_m, TranslationDistance(r.odom_from_cam, truth));
    worst_rad = std::max(worst_rad, RotationDistance(r.odom_from_cam, truth));
  }
  EXPECT_EQ(ok, 61);
  EXPECT_LT(worst_m, 1e-9);
  EXPECT_LT(worst_rad, 1e-9);
  EXPECT_EQ(sync.stats().synced, 61);
  EXPECT_EQ(sync.stats().before_first, 3);
  EXPECT_EQ(sync.stats().after_last, static_cast<int64_t>(images.size()) - 64);
  std::printf("interpolation on the screw trajectory: max error %.3g m, %.3g rad over %d images\n",
              worst_m, worst_rad, ok);
}

TEST(ImageOdometrySync, ImagesWaitForOdometryThenGiveUp) {
  const ScrewTrajectory screw;
  ImageOdometrySync sync(kBaseFromCam, 100000, 200000, 10);
  std::vector<ImageOdometry> out;
  const int64_t t0 = screw.t0_utime;
  sync.AddImage(ImageStamp{t0 + 10000, 0, ""}, &out);  // no odometry yet: waits
  EXPECT_TRUE(out.empty());
  EXPECT_EQ(sync.pending(), 1u);
  sync.AddOdometry(screw.Sample(t0, 0), &out);
  EXPECT_TRUE(out.empty());  // still newer than all odometry
  sync.AddOdometry(screw.Sample(t0 + 20000, 1), &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].result, InterpolationResult::kOk);
  out.clear();
  sync.AddImage(ImageStamp{t0 + 100000, 1, ""}, &out);   // waits
  sync.AddImage(ImageStamp{t0 + 400000, 2, ""}, &out);   // 0.3 s later: the first gives up
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].image.seq, 1);
  EXPECT_EQ(out[0].result, InterpolationResult::kAfterLast);
  out.clear();
  // A gap of 0.5 s in the odometry is too large (max 0.1 s).
  sync.AddOdometry(screw.Sample(t0 + 520000, 2), &out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].result, InterpolationResult::kGapTooLarge);
  EXPECT_EQ(sync.stats().in_gap, 1);
  // Out-of-order odometry is rejected and counted.
  sync.AddOdometry(screw.Sample(t0 + 100000, 3), &out);
  EXPECT_EQ(sync.stats().odometry_rejected, 1);
}

TEST(ImageOdometrySync, BoundedPendingQueue) {
  ImageOdometrySync sync(kBaseFromCam, 100000, 100 * kUsecPerSec, 3);
  std::vector<ImageOdometry> out;
  for (int i = 0; i < 5; ++i) sync.AddImage(ImageStamp{1000 * i, i, ""}, &out);
  EXPECT_EQ(sync.pending(), 3u);
  EXPECT_EQ(out.size(), 2u);
  EXPECT_EQ(sync.stats().pending_overflow, 2);
  sync.Flush(&out);
  EXPECT_EQ(out.size(), 5u);
  EXPECT_EQ(out.back().detail, "no odometry yet");
}

}  // namespace
}  // namespace mbslam
