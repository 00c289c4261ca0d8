#include "services/perception/tracking/patch_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace mbslam {

bool ExtractPatch(const cv::Mat& image, const Eigen::Vector2f& uv, int size, cv::Mat* patch) {
  const float half = 0.5f * static_cast<float>(size - 1);
  if (uv.x() - half < 0.0f || uv.y() - half < 0.0f || uv.x() + half > image.cols - 1.0f ||
      uv.y() + half > image.rows - 1.0f) {
    return false;
  }
  cv::getRectSubPix(image, cv::Size(size, size), cv::Point2f(uv.x(), uv.y()), *patch, CV_8U);
  return true;
}

float PatchNcc(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.empty()) return 0.0f;
  const int n = a.rows * a.cols;
  double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  for (int r = 0; r < a.rows; ++r) {
    const uint8_t* pa = a.ptr<uint8_t>(r);
    const uint8_t* pb = b.ptr<uint8_t>(r);
    for (int c = 0; c < a.cols; ++c) {
      const double x = pa[c], y = pb[c];
      sa += x;
      sb += y;
      saa += x * x;
      sbb += y * y;
      sab += x * y;
    }
  }
  const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
  if (va < 1e-6 * n || vb < 1e-6 * n) return 0.0f;
  return static_cast<float>((sab - sa * sb / n) / std::sqrt(va * vb));
}

PatchMatch FindPatchZssd(const cv::Mat& image, const cv::Mat& patch,
                         const Eigen::Vector2f& predicted, int radius) {
  PatchMatch best;
  const int size = patch.cols;
  const int half = size / 2;
  const int cx = static_cast<int>(std::lround(predicted.x()));
  const int cy = static_cast<int>(std::lround(predicted.y()));
  const int x0 = std::max(half, cx - radius), x1 = std::min(image.cols - 1 - half, cx + radius);
  const int y0 = std::max(half, cy - radius), y1 = std::min(image.rows - 1 - half, cy + radius);
  if (x0 > x1 || y0 > y1) return best;

  // ZSSD / n = (sum (i - t)^2 - (sum i - sum t)^2 / n) / n: one pass of exact integer
  // sums per position (at most 255^2 * n, n <= 31^2: fits 32 bits), no per-position mean
  // pass.
  const int n = size * size;
  int64_t tsum = 0;
  for (int r = 0; r < size; ++r) {
    const uint8_t* p = patch.ptr<uint8_t>(r);
    for (int c = 0; c < size; ++c) tsum += p[c];
  }
  const int w = x1 - x0 + 1, h = y1 - y0 + 1;
  cv::Mat scores(h, w, CV_32F);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      int64_t isum = 0, ssd = 0;
      for (int r = 0; r < size; ++r) {
        const uint8_t* ip = image.ptr<uint8_t>(y - half + r) + (x - half);
        const uint8_t* tp = patch.ptr<uint8_t>(r);
        int32_t row_sum = 0, row_ssd = 0;
        for (int c = 0; c < size; ++c) {
          const int32_t d = static_cast<int32_t>(ip[c]) - static_cast<int32_t>(tp[c]);
          row_sum += ip[c];
          row_ssd += d * d;
        }
        isum += row_sum;
        ssd += row_ssd;
      }
      const double diff = static_cast<double>(isum - tsum);
      scores.at<float>(y - y0, x - x0) =
          static_cast<float>((static_cast<double>(ssd) - diff * diff / n) / n);
    }
  }
  cv::Point min_loc;
  double min_val;
  cv::minMaxLoc(scores, &min_val, nullptr, &min_loc, nullptr);
  float second = std::numeric_limits<float>::max();
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (std::abs(x - min_loc.x) <= 2 && std::abs(y - min_loc.y) <= 2) continue;
      second = std::min(second, scores.at<float>(y, x));
    }
  }
  float dx = 0.0f, dy = 0.0f;
  auto parabola = [](float a, float b, float c) {
    const float denom = a - 2.0f * b + c;
    return std::abs(denom) > 1e-6f ? 0.5f * (a - c) / denom : 0.0f;
  };
  if (min_loc.x > 0 && min_loc.x < w - 1) {
    dx = parabola(scores.at<float>(min_loc.y, min_loc.x - 1), scores.at<float>(min_loc),
                  scores.at<float>(min_loc.y, min_loc.x + 1));
  }
  if (min_loc.y > 0 && min_loc.y < h - 1) {
    dy = parabola(scores.at<float>(min_loc.y - 1, min_loc.x), scores.at<float>(min_loc),
                  scores.at<float>(min_loc.y + 1, min_loc.x));
  }
  best.uv = Eigen::Vector2f(static_cast<float>(x0 + min_loc.x) + std::clamp(dx, -0.5f, 0.5f),
                            static_cast<float>(y0 + min_loc.y) + std::clamp(dy, -0.5f, 0.5f));
  best.score = static_cast<float>(min_val);
  best.second = second;
  best.found = true;
  return best;
}

}  // namespace mbslam
