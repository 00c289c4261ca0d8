#include "services/perception/tracking/patch_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/LU>

#include <opencv2/imgproc.hpp>

#include "common/util/simd_clones.h"

namespace mbslam {

namespace {

// Columns SampleRows16 computes per row; it reads one more.
constexpr int kSampleLanes = 16;

// ExtractPatch's fixed-width rows (kSampleLanes columns computed, `size` kept), in float, which
// vectorises (32-bit integer products do not, on baseline x86-64): every product and
// partial sum is an integer below 255 * 65538 < 2^24, exact in float, and scaling by
// 2^-16 is exact, so this is the integer arithmetic's result.
MBSLAM_SIMD_CLONES void SampleRows16(const cv::Mat& image, int ix, int iy, int size, int32_t w00, int32_t w01,
                                     int32_t w10, int32_t w11, cv::Mat* patch) {
  const float f00 = static_cast<float>(w00), f01 = static_cast<float>(w01);
  const float f10 = static_cast<float>(w10), f11 = static_cast<float>(w11);
  for (int r = 0; r < size; ++r) {
    const uint8_t* __restrict s0 = image.ptr<uint8_t>(iy + r) + ix;
    const uint8_t* __restrict s1 = image.ptr<uint8_t>(iy + r + 1) + ix;
    uint8_t row[kSampleLanes];
    for (int c = 0; c < kSampleLanes; ++c) {
      const float v = static_cast<float>(s0[c]) * f00 + static_cast<float>(s0[c + 1]) * f01 +
                      static_cast<float>(s1[c]) * f10 + static_cast<float>(s1[c + 1]) * f11;
      row[c] = static_cast<uint8_t>(static_cast<int32_t>((v + 32768.0f) * (1.0f / 65536.0f)));
    }
    std::copy(row, row + size, patch->ptr<uint8_t>(r));
  }
}

}  // namespace

bool ExtractPatch(const cv::Mat& image, const Eigen::Vector2f& uv, int size, cv::Mat* patch) {
  const float half = 0.5f * static_cast<float>(size - 1);
  if (uv.x() - half < 0.0f || uv.y() - half < 0.0f || uv.x() + half > image.cols - 1.0f ||
      uv.y() + half > image.rows - 1.0f) {
    return false;
  }
  // The corner sample and its bilinear weights, as cv::getRectSubPix takes them for
  // 8-bit images: float weights rounded to 16-bit fixed point, the sum rounded back.
  const float sx = uv.x() - half, sy = uv.y() - half;
  const int ix = static_cast<int>(std::floor(sx)), iy = static_cast<int>(std::floor(sy));
  if (image.type() != CV_8UC1 || ix + size >= image.cols || iy + size >= image.rows) {
    // The last column or row would read one past the image (at zero weight): OpenCV's
    // replicated border handles it.
    cv::getRectSubPix(image, cv::Size(size, size), cv::Point2f(uv.x(), uv.y()), *patch, CV_8U);
    return true;
  }
  const float a = sx - static_cast<float>(ix), b = sy - static_cast<float>(iy);
  const int32_t w00 = cvRound((1.0f - a) * (1.0f - b) * 65536.0f), w01 = cvRound(a * (1.0f - b) * 65536.0f);
  const int32_t w10 = cvRound((1.0f - a) * b * 65536.0f), w11 = cvRound(a * b * 65536.0f);
  // The rounded weights sum to at most 65536 + 2, so the result stays <= 255.
  patch->create(size, size, CV_8UC1);
  if (size <= kSampleLanes && ix + kSampleLanes + 1 <= image.cols) {
    SampleRows16(image, ix, iy, size, w00, w01, w10, w11, patch);
    return true;
  }
  for (int r = 0; r < size; ++r) {
    const uint8_t* __restrict s0 = image.ptr<uint8_t>(iy + r) + ix;
    const uint8_t* __restrict s1 = image.ptr<uint8_t>(iy + r + 1) + ix;
    uint8_t* __restrict out = patch->ptr<uint8_t>(r);
    for (int c = 0; c < size; ++c) {
      const int32_t v = s0[c] * w00 + s0[c + 1] * w01 + s1[c] * w10 + s1[c + 1] * w11;
      out[c] = static_cast<uint8_t>((v + (1 << 15)) >> 16);
    }
  }
  return true;
}

namespace {

// Sums of a, b, a^2, b^2 and ab over two 8-bit patches of the same size, in Acc.
// Continuous patches (the usual case) are summed as one run, which vectorises.
template <typename Acc>
void NccSums(const cv::Mat& a, const cv::Mat& b, Acc sums[5]) {
  Acc sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
  const bool flat = a.isContinuous() && b.isContinuous();
  const int rows = flat ? 1 : a.rows, cols = flat ? a.rows * a.cols : a.cols;
  for (int r = 0; r < rows; ++r) {
    const uint8_t* pa = a.ptr<uint8_t>(r);
    const uint8_t* pb = b.ptr<uint8_t>(r);
    for (int c = 0; c < cols; ++c) {
      const Acc x = pa[c], y = pb[c];
      sa += x;
      sb += y;
      saa += x * x;
      sbb += y * y;
      sab += x * y;
    }
  }
  sums[0] = sa, sums[1] = sb, sums[2] = saa, sums[3] = sbb, sums[4] = sab;
}

}  // namespace

float PatchNcc(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.empty() || a.type() != CV_8UC1 || b.type() != CV_8UC1) return 0.0f;
  const int n = a.rows * a.cols;
  // Integer sums are exact, as double sums of the bytes were, and they vectorise; 32 bits
  // hold them up to 255^2 * 66051 < 2^32 pixels.
  double s[5];
  if (n <= 66051) {
    uint32_t si[5];
    NccSums(a, b, si);
    for (int k = 0; k < 5; ++k) s[k] = si[k];
  } else {
    uint64_t si[5];
    NccSums(a, b, si);
    for (int k = 0; k < 5; ++k) s[k] = static_cast<double>(si[k]);
  }
  const double va = s[2] - s[0] * s[0] / n, vb = s[3] - s[1] * s[1] / n;
  if (va < 1e-6 * n || vb < 1e-6 * n) return 0.0f;
  return static_cast<float>((s[4] - s[0] * s[1] / n) / std::sqrt(va * vb));
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

namespace {

// Bilinear sample of a CV_32F image; the caller keeps (x, y) within
// [0, cols - 1] x [0, rows - 1].
float Bilinear(const cv::Mat& image, float x, float y) {
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
  const float* r0 = image.ptr<float>(y0);
  const float* r1 = image.ptr<float>(y0 + 1);
  return (1.0f - ay) * ((1.0f - ax) * r0[x0] + ax * r0[x0 + 1]) + ay * ((1.0f - ax) * r1[x0] + ax * r1[x0 + 1]);
}

}  // namespace

bool WarpReferencePatch(const cv::Mat& reference, const Eigen::Matrix2f& cur_from_ref, int side, cv::Mat* templ) {
  if (reference.empty() || reference.type() != CV_32F || reference.rows != reference.cols || side < 3) return false;
  const float det = cur_from_ref.determinant();
  if (!std::isfinite(det) || std::abs(det) < 1e-6f) return false;
  const Eigen::Matrix2f ref_from_cur = cur_from_ref.inverse();
  const float centre = 0.5f * static_cast<float>(reference.cols - 1);
  const float half = 0.5f * static_cast<float>(side - 1);
  // The patch's corners bound every sample (the warp is linear).
  const float reach = (ref_from_cur.cwiseAbs() * Eigen::Vector2f(half, half)).maxCoeff();
  if (!(reach <= centre)) return false;
  templ->create(side, side, CV_32F);
  const Eigen::Vector2f step_x = ref_from_cur.col(0);
  for (int y = 0; y < side; ++y) {
    float* row = templ->ptr<float>(y);
    Eigen::Vector2f p = Eigen::Vector2f::Constant(centre) + ref_from_cur * Eigen::Vector2f(-half, static_cast<float>(y) - half);
    for (int x = 0; x < side; ++x, p += step_x) row[x] = Bilinear(reference, p.x(), p.y());
  }
  return true;
}

PatchAlignment AlignPatch(const cv::Mat& image, const cv::Mat& templ, const Eigen::Vector2f& start,
                          int max_iterations, float tolerance_px) {
  PatchAlignment out;
  out.uv = start;
  const int n = templ.rows;
  if (templ.empty() || templ.type() != CV_32F || templ.cols != n || n < 5 || n % 2 == 0 || image.type() != CV_8U) {
    return out;
  }
  const int inner = n - 2;
  const int m = inner * inner;
  const float half = 0.5f * static_cast<float>(inner - 1);
  // Template values and gradients on the inner pixels, zero-mean (the bias is free, so the
  // mean gradient carries no information).
  std::vector<float> t(static_cast<size_t>(m)), tx(static_cast<size_t>(m)), ty(static_cast<size_t>(m));
  double tmean = 0.0, gxm = 0.0, gym = 0.0;
  for (int y = 1, k = 0; y < n - 1; ++y) {
    const float* r = templ.ptr<float>(y);
    const float* ru = templ.ptr<float>(y - 1);
    const float* rd = templ.ptr<float>(y + 1);
    for (int x = 1; x < n - 1; ++x, ++k) {
      t[k] = r[x];
      tx[k] = 0.5f * (r[x + 1] - r[x - 1]);
      ty[k] = 0.5f * (rd[x] - ru[x]);
      tmean += t[k];
      gxm += tx[k];
      gym += ty[k];
    }
  }
  tmean /= m;
  gxm /= m;
  gym /= m;
  double a = 0.0, b = 0.0, c = 0.0, tvar = 0.0;
  for (int k = 0; k < m; ++k) {
    t[k] -= static_cast<float>(tmean);
    tx[k] -= static_cast<float>(gxm);
    ty[k] -= static_cast<float>(gym);
    a += tx[k] * tx[k];
    b += tx[k] * ty[k];
    c += ty[k] * ty[k];
    tvar += t[k] * t[k];
  }
  const double det = a * c - b * b;
  if (!(a + c > 1.0) || !(det > 1e-6 * (a + c) * (a + c)) || !(tvar > 1e-6 * m)) return out;

  std::vector<float> w(static_cast<size_t>(m));
  // Samples the image under the template at `p`; the image's gain-normalised difference
  // from the template is returned through `ncc` and `w`.
  auto sample = [&](const Eigen::Vector2f& p, double* wvar_out) -> bool {
    if (!(p.x() - half >= 0.0f && p.y() - half >= 0.0f && p.x() + half <= image.cols - 1.0f &&
          p.y() + half <= image.rows - 1.0f)) {
      return false;
    }
    // A translated patch: every sample has the same bilinear weights.
    const float left = p.x() - half, top = p.y() - half;
    const int x0 = std::min(static_cast<int>(left), image.cols - 1 - inner);
    const int y0 = std::min(static_cast<int>(top), image.rows - 1 - inner);
    const float ax = left - static_cast<float>(x0), ay = top - static_cast<float>(y0);
    const float w00 = (1.0f - ay) * (1.0f - ax), w01 = (1.0f - ay) * ax, w10 = ay * (1.0f - ax), w11 = ay * ax;
    double wmean = 0.0;
    for (int y = 0, k = 0; y < inner; ++y) {
      const uint8_t* r0 = image.ptr<uint8_t>(y0 + y) + x0;
      const uint8_t* r1 = image.ptr<uint8_t>(y0 + y + 1) + x0;
      float row_sum = 0.0f;
      for (int x = 0; x < inner; ++x, ++k) {
        w[k] = w00 * r0[x] + w01 * r0[x + 1] + w10 * r1[x] + w11 * r1[x + 1];
        row_sum += w[k];
      }
      wmean += row_sum;
    }
    wmean /= m;
    double wvar = 0.0;
    for (int k = 0; k < m; ++k) {
      w[k] -= static_cast<float>(wmean);
      wvar += static_cast<double>(w[k]) * w[k];
    }
    *wvar_out = wvar;
    return wvar > 1e-6 * m;
  };
  Eigen::Vector2f p = start;
  for (int it = 0; it < max_iterations; ++it) {
    double wvar = 0.0;
    if (!sample(p, &wvar)) return out;
    // The image's contrast scaled to the template's (gain), then the Gauss-Newton step of
    // the template's shift; the image position moves the opposite way.
    const float gain = static_cast<float>(std::sqrt(tvar / wvar));
    double bx = 0.0, by = 0.0;
    for (int k = 0; k < m; ++k) {
      const float e = gain * w[k] - t[k];
      bx += tx[k] * e;
      by += ty[k] * e;
    }
    const Eigen::Vector2f step(static_cast<float>((c * bx - b * by) / det), static_cast<float>((a * by - b * bx) / det));
    if (!step.allFinite()) return out;
    p -= step;
    out.iterations = it + 1;
    if (step.squaredNorm() < tolerance_px * tolerance_px) {
      out.converged = true;
      break;
    }
  }
  double wvar = 0.0;
  if (!sample(p, &wvar)) {
    out.converged = false;
    return out;
  }
  double cross = 0.0;
  for (int k = 0; k < m; ++k) cross += static_cast<double>(w[k]) * t[k];
  out.ncc = static_cast<float>(cross / std::sqrt(wvar * tvar));
  out.uv = p;
  return out;
}

double PatchCornerRatio(const cv::Mat& patch) {
  if (patch.empty() || patch.rows < 3 || patch.cols < 3 || patch.channels() != 1) return 0.0;
  cv::Mat f;
  patch.convertTo(f, CV_64F);
  double a = 0.0, b = 0.0, c = 0.0;
  for (int y = 1; y + 1 < f.rows; ++y) {
    for (int x = 1; x + 1 < f.cols; ++x) {
      const double gx = 0.5 * (f.at<double>(y, x + 1) - f.at<double>(y, x - 1));
      const double gy = 0.5 * (f.at<double>(y + 1, x) - f.at<double>(y - 1, x));
      a += gx * gx;
      b += gx * gy;
      c += gy * gy;
    }
  }
  if (!std::isfinite(a + b + c)) return 0.0;
  const double half_trace = 0.5 * (a + c);
  const double disc = std::hypot(0.5 * (a - c), b);  // no cancellation, never negative
  const double large = half_trace + disc;
  if (!(large > 0.0)) return 0.0;
  return std::max(0.0, half_trace - disc) / large;
}

}  // namespace mbslam
