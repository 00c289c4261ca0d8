#include "services/perception/tracking/klt.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "services/perception/tracking/test_images.h"

namespace mbslam {
namespace {

using testing_images::Shift;
using testing_images::Texture;

std::vector<cv::Mat> Pyramid(const cv::Mat& img, int max_level, bool derivatives) {
  std::vector<cv::Mat> p;
  cv::buildOpticalFlowPyramid(img, p, cv::Size(21, 21), max_level, derivatives);
  return p;
}

// Interior points on a grid (away from the border, where the shifted image is reflected).
std::vector<cv::Point2f> Grid(const cv::Mat& img, int margin, int step) {
  std::vector<cv::Point2f> pts;
  for (int y = margin; y < img.rows - margin; y += step) {
    for (int x = margin; x < img.cols - margin; x += step) pts.emplace_back(x + 0.3f, y + 0.6f);
  }
  return pts;
}

struct ErrorStats {
  double median = 0.0, max = 0.0;
  int tracked = 0;
};

ErrorStats Errors(const std::vector<cv::Point2f>& pts, const std::vector<cv::Point2f>& next,
                  const std::vector<uint8_t>& status, cv::Point2f shift) {
  std::vector<double> e;
  for (size_t i = 0; i < pts.size(); ++i) {
    if (!status[i]) continue;
    const cv::Point2f d = next[i] - pts[i] - shift;
    e.push_back(std::sqrt(d.dot(d)));
  }
  ErrorStats s;
  s.tracked = static_cast<int>(e.size());
  if (e.empty()) return s;
  std::sort(e.begin(), e.end());
  s.median = e[e.size() / 2];
  s.max = e.back();
  return s;
}

// The float pyramid is the byte pyramid's grey levels, border included (the same
// readable range around each level), and skips derivative levels.
TEST(Klt, FloatPyramidKeepsTheLevelsAndTheirBorder) {
  const cv::Mat a = Texture(160, 120, 5);
  for (const bool derivatives : {false, true}) {
    const std::vector<cv::Mat> bytes = Pyramid(a, 2, derivatives);
    const KltPyramid floats = MakeKltPyramid(bytes);
    ASSERT_EQ(floats.levels.size(), 3u) << derivatives;
    for (size_t l = 0; l < floats.levels.size(); ++l) {
      const cv::Mat& b = bytes[derivatives ? 2 * l : l];
      const cv::Mat& f = floats.levels[l];
      ASSERT_EQ(f.type(), CV_32FC1);
      ASSERT_EQ(f.size(), b.size());
      cv::Size bw, fw;
      cv::Point bo, fo;
      b.locateROI(bw, bo);
      f.locateROI(fw, fo);
      EXPECT_EQ(fw, bw);
      EXPECT_EQ(fo, bo);
      cv::Mat bb = b, ff = f;
      bb.adjustROI(bo.y, bw.height - bo.y - b.rows, bo.x, bw.width - bo.x - b.cols);
      ff.adjustROI(fo.y, fw.height - fo.y - f.rows, fo.x, fw.width - fo.x - f.cols);
      cv::Mat converted;
      bb.convertTo(converted, CV_32F);
      EXPECT_EQ(cv::norm(converted, ff, cv::NORM_INF), 0.0) << "level " << l;
    }
  }
  EXPECT_TRUE(MakeKltPyramid({}).empty());
}

TEST(Klt, SubpixelShiftAsAccurateAsOpenCv) {
  const cv::Mat a = Texture(320, 240, 3);
  const cv::Point2f shift(2.3f, -1.7f);
  const cv::Mat b = Shift(a, shift.x, shift.y);
  const std::vector<cv::Point2f> pts = Grid(a, 30, 12);
  // Ours, from zero motion.
  std::vector<cv::Point2f> next = pts;
  std::vector<uint8_t> status;
  KltParams params;
  TrackPointsKlt(Pyramid(a, 2, false), Pyramid(b, 2, false), pts, &next, &status, params);
  const ErrorStats ours = Errors(pts, next, status, shift);
  // OpenCV's, with the same window, levels and criteria.
  std::vector<cv::Point2f> cv_next = pts;
  std::vector<uint8_t> cv_status;
  std::vector<float> err;
  cv::calcOpticalFlowPyrLK(Pyramid(a, 2, true), Pyramid(b, 2, true), pts, cv_next, cv_status, err, cv::Size(15, 15), 2,
                           cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 12, 0.05),
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  const ErrorStats theirs = Errors(pts, cv_next, cv_status, shift);
  EXPECT_EQ(ours.tracked, static_cast<int>(pts.size()));
  EXPECT_LT(ours.median, 0.05);
  EXPECT_LT(ours.max, 0.25);
  EXPECT_LE(ours.median, 1.5 * theirs.median + 0.01) << "OpenCV median " << theirs.median;
  std::printf("median / max error (px): ours %.4f / %.4f, OpenCV %.4f / %.4f\n", ours.median, ours.max, theirs.median,
              theirs.max);
}

TEST(Klt, LargeMotionThroughThePyramid) {
  const cv::Mat a = Texture(400, 300, 5);
  const cv::Point2f shift(17.4f, 9.2f);
  const cv::Mat b = Shift(a, shift.x, shift.y);
  const std::vector<cv::Point2f> pts = Grid(a, 50, 15);
  std::vector<cv::Point2f> next = pts;
  std::vector<uint8_t> status;
  KltParams params;
  params.max_level = 3;
  TrackPointsKlt(Pyramid(a, 3, false), Pyramid(b, 3, false), pts, &next, &status, params);
  const ErrorStats s = Errors(pts, next, status, shift);
  EXPECT_GE(s.tracked, static_cast<int>(0.95 * static_cast<double>(pts.size())));
  EXPECT_LT(s.median, 0.05);
  // Level 0 alone cannot reach a 20-px motion from zero: the pyramid is what does it.
  std::vector<cv::Point2f> flat_next = pts;
  params.max_level = 0;
  TrackPointsKlt(Pyramid(a, 3, false), Pyramid(b, 3, false), pts, &flat_next, &status, params);
  EXPECT_GT(Errors(pts, flat_next, status, shift).median, 1.0);
}

TEST(Klt, PointsAreIndependentAndDerivativeLevelsAreIgnored) {
  const cv::Mat a = Texture(320, 240, 7);
  const cv::Mat b = Shift(a, -3.1f, 1.4f);
  const std::vector<cv::Point2f> pts = Grid(a, 20, 10);
  KltParams params;
  std::vector<cv::Point2f> all = pts;
  std::vector<uint8_t> all_status;
  TrackPointsKlt(Pyramid(a, 2, false), Pyramid(b, 2, false), pts, &all, &all_status, params);
  // A subset tracked alone, on pyramids with derivative levels interleaved.
  const std::vector<cv::Point2f> part(pts.begin() + 7, pts.begin() + 40);
  std::vector<cv::Point2f> part_next = part;
  std::vector<uint8_t> part_status;
  TrackPointsKlt(Pyramid(a, 2, true), Pyramid(b, 2, true), part, &part_next, &part_status, params);
  for (size_t i = 0; i < part.size(); ++i) {
    EXPECT_EQ(part_next[i], all[i + 7]);
    EXPECT_EQ(part_status[i], all_status[i + 7]);
  }
}

TEST(Klt, OutsideNanAndFlatPointsFailCleanly) {
  cv::Mat a = Texture(320, 240, 9);
  a(cv::Rect(200, 100, 80, 80)).setTo(128);  // a flat square: nothing to track
  const cv::Mat b = Shift(a, 1.0f, 0.5f);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const std::vector<cv::Point2f> pts = {{-40.0f, 10.0f}, {10.0f, 1000.0f}, {nan, 50.0f}, {240.0f, 140.0f},
                                        {100.0f, 100.0f}};
  std::vector<cv::Point2f> next = pts;
  next[4] = {1e9f, 1e9f};  // a wild initial guess for a good point
  std::vector<uint8_t> status;
  KltParams params;
  TrackPointsKlt(Pyramid(a, 2, false), Pyramid(b, 2, false), pts, &next, &status, params);
  ASSERT_EQ(status.size(), pts.size());
  EXPECT_EQ(status[0], 0);
  EXPECT_EQ(status[1], 0);
  EXPECT_EQ(status[2], 0);
  EXPECT_EQ(status[3], 0) << "flat window";
  EXPECT_EQ(status[4], 0) << "guess far outside the image";
  // Bad parameters: nothing tracked, nothing read.
  params.window_px = 14;
  TrackPointsKlt(Pyramid(a, 2, false), Pyramid(b, 2, false), pts, &next, &status, params);
  EXPECT_EQ(std::count(status.begin(), status.end(), 1), 0);
}

TEST(Klt, EveryWindowSizeTracks) {
  const cv::Mat a = Texture(320, 240, 11);
  const cv::Point2f shift(1.6f, 2.2f);
  const cv::Mat b = Shift(a, shift.x, shift.y);
  const std::vector<cv::Point2f> pts = Grid(a, 40, 20);
  for (int w : {7, 9, 13, 15, 21, 31, 41}) {
    std::vector<cv::Point2f> next = pts;
    std::vector<uint8_t> status;
    KltParams params;
    params.window_px = w;
    TrackPointsKlt(Pyramid(a, 2, false), Pyramid(b, 2, false), pts, &next, &status, params);
    const ErrorStats s = Errors(pts, next, status, shift);
    EXPECT_GE(s.tracked, static_cast<int>(0.95 * static_cast<double>(pts.size()))) << "window " << w;
    EXPECT_LT(s.median, 0.08) << "window " << w;
  }
}

// Against OpenCV's implementation on a rotating, zooming view, with points up to the
// image border (where only the image proper may count): the same points tracked, to the
// same place.
TEST(Klt, AgreesWithOpenCvUpToTheBorder) {
  const cv::Mat a = Texture(320, 240, 13);
  cv::Mat b;
  const cv::Mat m = cv::getRotationMatrix2D(cv::Point2f(150.0f, 110.0f), 2.0, 1.02);
  cv::warpAffine(a, b, m, a.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  std::vector<cv::Point2f> pts;
  for (int y = 2; y < a.rows - 2; y += 9) {
    for (int x = 2; x < a.cols - 2; x += 9) pts.emplace_back(x + 0.25f, y + 0.75f);
  }
  std::vector<cv::Point2f> ours = pts, theirs = pts;
  std::vector<uint8_t> s1, s2;
  std::vector<float> err;
  TrackPointsKlt(Pyramid(a, 2, false), Pyramid(b, 2, false), pts, &ours, &s1, KltParams());
  cv::calcOpticalFlowPyrLK(Pyramid(a, 2, true), Pyramid(b, 2, true), pts, theirs, s2, err, cv::Size(15, 15), 2,
                           cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 12, 0.05),
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  int same_status = 0, both = 0, close = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    same_status += s1[i] == s2[i];
    if (s1[i] && s2[i]) {
      ++both;
      close += cv::norm(ours[i] - theirs[i]) < 0.05;
    }
  }
  const double n = static_cast<double>(pts.size());
  std::printf("%zu points: same status %d, both tracked %d, of which within 0.05 px %d\n", pts.size(), same_status,
              both, close);
  EXPECT_GE(same_status, static_cast<int>(0.97 * n));
  EXPECT_GE(close, static_cast<int>(0.97 * static_cast<double>(both)));
}

}  // namespace
}  // namespace mbslam
