#include "tools/eval/plot.h"

#include <gtest/gtest.h>

#include <cmath>

namespace mbslam {
namespace eval {
namespace {

int CountColor(const cv::Mat& img, const cv::Vec3b& color, int tolerance) {
  int n = 0;
  for (int r = 0; r < img.rows; ++r) {
    for (int c = 0; c < img.cols; ++c) {
      const cv::Vec3b p = img.at<cv::Vec3b>(r, c);
      if (std::abs(p[0] - color[0]) <= tolerance && std::abs(p[1] - color[1]) <= tolerance &&
          std::abs(p[2] - color[2]) <= tolerance) {
        ++n;
      }
    }
  }
  return n;
}

TEST(Plot, DrawsTruthAndEstimate) {
  Trajectory gt, est;
  for (int i = 0; i < 100; ++i) {
    const double a = 0.06 * i;
    gt.push_back({i * 1000, Rigid3d(Eigen::Quaterniond::Identity(),
                                    Eigen::Vector3d(5 * std::cos(a), 3 * std::sin(a), 0.1))});
    est.push_back({i * 1000, Rigid3d(Eigen::Quaterniond::Identity(),
                                     Eigen::Vector3d(5.3 * std::cos(a), 3.2 * std::sin(a), 0.1))});
  }
  TopViewPlot options;
  options.title = "test";
  cv::Mat img;
  ASSERT_TRUE(DrawTopView(gt, est, options, &img).ok());
  EXPECT_EQ(img.size(), cv::Size(900, 700));
  EXPECT_GT(CountColor(img, cv::Vec3b(40, 160, 40), 10), 300);  // green truth
  EXPECT_GT(CountColor(img, cv::Vec3b(40, 40, 220), 10), 300);  // red estimate
  EXPECT_FALSE(DrawTopView(Trajectory(), Trajectory(), options, &img).ok());
  // A standing camera still gives a picture.
  Trajectory still(3, TimedPose{0, Rigid3d()});
  EXPECT_TRUE(DrawTopView(still, still, options, &img).ok());
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
