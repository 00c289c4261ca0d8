#include "services/perception/pipeline/perception_core.h"

#include <memory>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace mbslam {
namespace {

cv::Mat Texture(int w, int h, int seed) {
  cv::Mat noise(h / 4, w / 4, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat big;
  cv::resize(noise, big, cv::Size(w, h), 0, 0, cv::INTER_CUBIC);
  cv::GaussianBlur(big, big, cv::Size(3, 3), 0.8);
  return big;
}

ImageFrame Frame(const cv::Mat& gray, int64_t k, const std::shared_ptr<const CameraIntrinsics>& K) {
  ImageFrame f;
  f.utime = 1000000 + k * 33333;
  f.seq = k;
  f.gray = gray;
  f.intrinsics = K;
  return f;
}

std::shared_ptr<const CameraIntrinsics> Intrinsics() {
  auto K = std::make_shared<CameraIntrinsics>();
  K->width = 640;
  K->height = 480;
  K->fx = K->fy = 525.0;
  K->cx = 319.5;
  K->cy = 239.5;
  return K;
}

cv::Mat Shifted(const cv::Mat& img, double dx) {
  const cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, 0);
  cv::Mat out;
  cv::warpAffine(img, out, M, img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

// KLT windows wider than the pyramid's default border (21) used to abort in OpenCV.
TEST(PerceptionCoreTest, WideKltWindowRuns) {
  CoreOptions options;
  options.tracking.klt_window_px = 31;
  options.tracking.klt_fast_window_px = 35;
  options.slam.background_ba = false;
  ASSERT_TRUE(options.tracking.Check());
  Counters counters;
  StageTimers timers;
  PerceptionCore core(options, &counters, &timers);
  const cv::Mat base = Texture(640, 480, 3);
  const auto K = Intrinsics();
  for (int k = 0; k < 4; ++k) core.ProcessFrame(Frame(Shifted(base, 2.0 * k), k, K));
  core.Finish();
  SUCCEED();
}

// A core (BA in the calling thread) that has tracked five images of a texture moving
// 2 px per image: images 0-4, Shifted(base, 2 k).
struct WarmCore {
  CoreOptions options = [] {
    CoreOptions o;
    o.slam.background_ba = false;
    return o;
  }();
  Counters counters;
  StageTimers timers;
  PerceptionCore core{options, &counters, &timers};
  cv::Mat base = Texture(640, 480, 4);
  std::shared_ptr<const CameraIntrinsics> K = Intrinsics();
  WarmCore() {
    for (int k = 0; k < 5; ++k) core.ProcessFrame(Frame(Shifted(base, 2.0 * k), k, K));
  }
};

// A glitch image between good ones is rejected and counted, with no pose, and the images
// after it are processed as if it had not come.
TEST(PerceptionCoreTest, GlitchImageIsCountedAndSkipped) {
  WarmCore w;
  auto& [options, counters, timers, core, base, K] = w;
  const FrameResult r = core.ProcessFrame(Frame(Texture(640, 480, 99), 5, K));
  EXPECT_EQ(counters.Get(counter::kImageRejectedGlitch), 1);
  EXPECT_NE(r.camera_pose.tracking_state, TrackingState::kOk);
  EXPECT_TRUE(r.tracks.empty());
  const FrameResult next = core.ProcessFrame(Frame(Shifted(base, 12.0), 6, K));
  EXPECT_EQ(counters.Get(counter::kImageRejectedGlitch), 1);
  EXPECT_GT(next.tracks.size(), 100u) << "the tracks survived the glitch";
  core.Finish();
}

// An exposure step is undone and counted, not rejected as a glitch: the tracks follow it.
TEST(PerceptionCoreTest, ExposureStepIsCountedAndTracked) {
  WarmCore w;
  auto& [options, counters, timers, core, base, K] = w;
  cv::Mat brighter;
  Shifted(base, 10.0).convertTo(brighter, CV_8U, 0.5, 110.0);
  const FrameResult r = core.ProcessFrame(Frame(brighter, 5, K));
  EXPECT_EQ(counters.Get(counter::kImageRejectedGlitch), 0);
  EXPECT_EQ(counters.Get(counter::kImageExposureCorrected), 1);
  EXPECT_GT(r.tracks.size(), 100u);
  const FrameResult next = core.ProcessFrame(Frame(Shifted(base, 12.0), 6, K));
  EXPECT_EQ(counters.Get(counter::kImageRejectedGlitch), 0);
  EXPECT_GT(next.tracks.size(), 100u);
  core.Finish();
}

}  // namespace
}  // namespace mbslam
