#include "tools/sim/procedural_texture.h"

#include <gtest/gtest.h>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace mbslam {
namespace sim {
namespace {

const TextureStyle kStyles[] = {
    TextureStyle::kAsphalt,  TextureStyle::kGrass,   TextureStyle::kPaving,   TextureStyle::kFacade,
    TextureStyle::kConcrete, TextureStyle::kVehicle, TextureStyle::kClothing, TextureStyle::kCrate};

TEST(ProceduralTexture, DeterministicPerSeed) {
  for (TextureStyle style : kStyles) {
    const cv::Mat a = MakeTexture(style, 200, 150, 0.01, 42);
    const cv::Mat b = MakeTexture(style, 200, 150, 0.01, 42);
    const cv::Mat c = MakeTexture(style, 200, 150, 0.01, 43);
    ASSERT_EQ(a.type(), CV_8UC3);
    ASSERT_EQ(a.size(), cv::Size(200, 150));
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << TextureStyleName(style);
    EXPECT_GT(cv::norm(a, c, cv::NORM_L1), 0.0) << TextureStyleName(style);
  }
}

// Every style has corners at several scales (FAST on an image pyramid), so features
// can be detected whether a surface is near or far.
TEST(ProceduralTexture, RichInCornersAtEveryScale) {
  for (TextureStyle style : kStyles) {
    cv::Mat gray;
    cv::cvtColor(MakeTexture(style, 512, 512, 0.006, 7), gray, cv::COLOR_BGR2GRAY);
    for (int level = 0; level < 3; ++level) {
      std::vector<cv::KeyPoint> kps;
      cv::FAST(gray, kps, 12, true);
      const double per_10k_px =
          1e4 * static_cast<double>(kps.size()) / static_cast<double>(gray.total());
      EXPECT_GT(per_10k_px, 5.0) << TextureStyleName(style) << " level " << level;
      cv::pyrDown(gray, gray);
    }
  }
}

// No repeated pattern: a patch's best match elsewhere in the texture (normalised
// cross-correlation) is clearly worse than at its own position. A single patch may lie
// on a long straight edge (a stripe, a plank) and match along it, so the median over a
// grid of patches is what must be low; a periodic texture fails for every patch.
TEST(ProceduralTexture, NoRepetitivePattern) {
  for (TextureStyle style : kStyles) {
    cv::Mat gray;
    cv::cvtColor(MakeTexture(style, 400, 400, 0.006, 11), gray, cv::COLOR_BGR2GRAY);
    std::vector<double> best;
    for (int py = 40; py < 360; py += 80) {
      for (int px = 40; px < 360; px += 80) {
        const cv::Rect patch(px, py, 31, 31);
        cv::Mat score;
        cv::matchTemplate(gray, gray(patch), score, cv::TM_CCOEFF_NORMED);
        EXPECT_NEAR(score.at<float>(patch.y, patch.x), 1.0, 1e-4);
        cv::rectangle(score, cv::Rect(patch.x - 10, patch.y - 10, 21, 21), cv::Scalar(-1),
                      cv::FILLED);
        double b;
        cv::minMaxLoc(score, nullptr, &b);
        best.push_back(b);
      }
    }
    std::sort(best.begin(), best.end());
    RecordProperty(std::string("median_best_ncc_") + TextureStyleName(style),
                   std::to_string(best[best.size() / 2]));
    EXPECT_LT(best[best.size() / 2], 0.85) << TextureStyleName(style);
  }
  // The test can fail: a tiled texture repeats.
  cv::Mat tile;
  cv::cvtColor(MakeTexture(TextureStyle::kAsphalt, 100, 100, 0.006, 11), tile, cv::COLOR_BGR2GRAY);
  cv::Mat tiled;
  cv::repeat(tile, 4, 4, tiled);
  cv::Mat score;
  cv::matchTemplate(tiled, tiled(cv::Rect(120, 120, 31, 31)), score, cv::TM_CCOEFF_NORMED);
  cv::rectangle(score, cv::Rect(110, 110, 21, 21), cv::Scalar(-1), cv::FILLED);
  double tiled_best;
  cv::minMaxLoc(score, nullptr, &tiled_best);
  EXPECT_GT(tiled_best, 0.99);
}

TEST(FractalNoise, ZeroMeanUnitVariance) {
  const cv::Mat n = FractalNoise(300, 200, 3, 64.0, 5, 0.6);
  cv::Scalar mean, stddev;
  cv::meanStdDev(n, mean, stddev);
  EXPECT_NEAR(mean[0], 0.0, 1e-4);
  EXPECT_NEAR(stddev[0], 1.0, 1e-4);
}

}  // namespace
}  // namespace sim
}  // namespace mbslam
