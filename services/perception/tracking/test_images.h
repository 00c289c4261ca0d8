#pragma once
// Test images for the tracking tests: a band-limited random texture (fine and coarse
// blobs, good corners everywhere) and its sub-pixel shift.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace mbslam {
namespace testing_images {

inline cv::Mat Texture(int w, int h, int seed) {
  cv::RNG rng(seed);
  cv::Mat noise(h, w, CV_8UC1);
  rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
  cv::Mat fine, coarse, out;
  cv::GaussianBlur(noise, fine, cv::Size(0, 0), 1.5);
  cv::GaussianBlur(noise, coarse, cv::Size(0, 0), 5.0);
  cv::addWeighted(fine, 1.0, coarse, 2.0, -128, out);
  return out;
}

inline cv::Mat Shift(const cv::Mat& img, float dx, float dy) {
  cv::Mat m = (cv::Mat_<double>(2, 3) << 1, 0, dx, 0, 1, dy);
  cv::Mat out;
  cv::warpAffine(img, out, m, img.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}

}  // namespace testing_images
}  // namespace mbslam
