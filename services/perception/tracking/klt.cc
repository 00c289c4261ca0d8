#include "services/perception/tracking/klt.h"

#include <algorithm>
#include <cmath>

#include "common/util/simd_clones.h"

namespace mbslam {
namespace {

// One pyramid level: the image (grey levels as floats) and how far outside it the buffer
// (the pyramid's border) can be read.
struct Level {
  const float* origin = nullptr;  // pixel (0, 0)
  size_t step = 0;                // floats per row
  int x_min = 0, x_max = -1, y_min = 0, y_max = -1;  // readable pixel range, inclusive
  int cols = 0, rows = 0;  // the image proper
};

std::vector<Level> Levels(const KltPyramid& pyramid) {
  std::vector<Level> levels;
  for (const cv::Mat& m : pyramid.levels) {
    cv::Size whole;
    cv::Point ofs;
    m.locateROI(whole, ofs);
    Level l;
    l.origin = m.ptr<float>(0);
    l.step = m.step[0] / sizeof(float);
    l.x_min = -ofs.x;
    l.y_min = -ofs.y;
    l.x_max = whole.width - ofs.x - 1;
    l.y_max = whole.height - ofs.y - 1;
    l.cols = m.cols;
    l.rows = m.rows;
    levels.push_back(l);
  }
  return levels;
}

// Bilinear samples of a block `rows` x C whose top-left corner is (x, y) + (ax, ay), ax, ay
// in [0, 1): out[r * C + c]. C is a compile-time multiple of 4, so that the row loop
// vectorises without a remainder. The caller has checked that rows y .. y + rows and
// columns x .. x + C are readable.
template <int C>
inline void SampleBlock(const Level& l, int x, int y, float ax, float ay, int rows, float* __restrict out) {
  const float w00 = (1.0f - ax) * (1.0f - ay), w01 = ax * (1.0f - ay);
  const float w10 = (1.0f - ax) * ay, w11 = ax * ay;
  for (int r = 0; r < rows; ++r) {
    const float* __restrict r0 =
        l.origin + static_cast<std::ptrdiff_t>(y + r) * static_cast<std::ptrdiff_t>(l.step) + x;
    const float* __restrict r1 = r0 + l.step;
    float* __restrict o = out + r * C;
    for (int c = 0; c < C; ++c) {
      o[c] = w00 * r0[c] + w01 * r0[c + 1] + w10 * r1[c] + w11 * r1[c + 1];
    }
  }
}

// A coordinate that converts to int safely (not NaN, not huge).
inline bool Sane(float v) { return std::abs(v) < 1e8f; }

inline bool Readable(const Level& l, int x, int y, int cols, int rows) {
  return x >= l.x_min && y >= l.y_min && x + cols <= l.x_max && y + rows <= l.y_max;
}

// Tracks the points with windows of side w <= WP, WP a multiple of 4: the arrays are WP
// wide, the columns past w carry zero gradient (they add nothing). Compiled twice, for
// AVX2 and for the baseline, the better one picked at load time: the loops are
// element-wise (their sums are per column), so both give the same bits.
template <int WP>
MBSLAM_SIMD_CLONES void TrackRange(const std::vector<Level>& lf, const std::vector<Level>& lt, int top, int w,
                const std::vector<cv::Point2f>& pts, std::vector<cv::Point2f>* next,
                std::vector<uint8_t>* status, const KltParams& params) {
  constexpr int TW = WP + 4;  // template width: the window, a one-pixel ring, rounded up to 4
  // Scharr's derivative (3, 10, 3 across, central difference along; / 32: grey levels per
  // pixel): smoother than a plain central difference, as OpenCV's derivative levels are.
  constexpr float kSide = 3.0f / 32.0f, kCentre = 10.0f / 32.0f;
  const float half = 0.5f * static_cast<float>(w - 1);
  const float eps2 = static_cast<float>(params.epsilon_px * params.epsilon_px);
  const double min_eigen = params.min_eigen * static_cast<double>(w * w);
  alignas(16) float templ[(WP + 2) * TW];
  alignas(16) float inner[WP * WP], gx[WP * WP], gy[WP * WP], warped[WP * WP];
  for (size_t i = 0; i < pts.size(); ++i) {
    bool ok = true;
    cv::Point2f guess = (*next)[i] * (1.0f / static_cast<float>(1 << top));
    for (int level = top; level >= 0; --level) {
      if (level != top) guess *= 2.0f;
      const Level& I = lf[static_cast<size_t>(level)];
      const Level& J = lt[static_cast<size_t>(level)];
      const cv::Point2f p = pts[i] * (1.0f / static_cast<float>(1 << level));
      // The template: the window around p, plus a one-pixel ring.
      const float tx = p.x - half - 1.0f, ty = p.y - half - 1.0f;
      const float fx = std::floor(tx), fy = std::floor(ty);
      if (!Sane(fx) || !Sane(fy) ||
          !Readable(I, static_cast<int>(fx), static_cast<int>(fy), TW, w + 2)) {
        if (level == 0) ok = false;
        continue;
      }
      SampleBlock<TW>(I, static_cast<int>(fx), static_cast<int>(fy), tx - fx, ty - fy, w + 2, templ);
      // Gradient (Scharr) and the normal matrix, summed per column first:
      // that vectorises without reordering a float reduction.
      alignas(16) float a11c[WP] = {}, a12c[WP] = {}, a22c[WP] = {};
      // Only the image proper counts: the pyramid's border (a reflection) carries no motion.
      // Each template pixel's gradient is weighted by the share of its bilinear support
      // inside the image (OpenCV's derivative levels are zero outside it), and columns
      // past the window by zero.
      const int x0 = static_cast<int>(fx) + 1, y0 = static_cast<int>(fy) + 1;
      const float ax = tx - fx, ay = ty - fy;
      auto inside = [](int v, int size) { return v >= 0 && v < size ? 1.0f : 0.0f; };
      // Away from the border every support is inside: the same weights, (1 - a) + a, with
      // the same bits, without testing each column and row.
      const bool cols_inside = x0 >= 0 && x0 + w < I.cols, rows_inside = y0 >= 0 && y0 + w < I.rows;
      const float inside_x = (1.0f - ax) + ax, inside_y = (1.0f - ay) + ay;
      alignas(16) float live[WP];
      for (int c = 0; c < WP; ++c) {
        live[c] = c >= w        ? 0.0f
                  : cols_inside ? inside_x
                                : (1.0f - ax) * inside(x0 + c, I.cols) + ax * inside(x0 + c + 1, I.cols);
      }
      for (int r = 0; r < w; ++r) {
        const float row_live =
            rows_inside ? inside_y : (1.0f - ay) * inside(y0 + r, I.rows) + ay * inside(y0 + r + 1, I.rows);
        const float* __restrict up = templ + r * TW + 1;
        const float* __restrict mid = up + TW;
        const float* __restrict down = mid + TW;
        float* __restrict in = inner + r * WP;
        float* __restrict dx = gx + r * WP;
        float* __restrict dy = gy + r * WP;
        for (int c = 0; c < WP; ++c) {
          in[c] = mid[c];
          dx[c] = row_live * live[c] * (kSide * (up[c + 1] - up[c - 1] + down[c + 1] - down[c - 1]) +
                             kCentre * (mid[c + 1] - mid[c - 1]));
          dy[c] = row_live * live[c] * (kSide * (down[c - 1] - up[c - 1] + down[c + 1] - up[c + 1]) +
                             kCentre * (down[c] - up[c]));
          a11c[c] += dx[c] * dx[c];
          a12c[c] += dx[c] * dy[c];
          a22c[c] += dy[c] * dy[c];
        }
      }
      double a11 = 0.0, a12 = 0.0, a22 = 0.0;
      for (int c = 0; c < WP; ++c) {
        a11 += a11c[c];
        a12 += a12c[c];
        a22 += a22c[c];
      }
      const double det = a11 * a22 - a12 * a12;
      const double min_eig = 0.5 * (a11 + a22 - std::sqrt((a11 - a22) * (a11 - a22) + 4.0 * a12 * a12));
      if (min_eig < min_eigen || det < 1e-12) {
        if (level == 0) ok = false;
        continue;
      }
      const double inv_det = 1.0 / det;
      cv::Point2f prev_delta(0.0f, 0.0f);
      for (int it = 0; it < params.max_iterations; ++it) {
        const float qx = guess.x - half, qy = guess.y - half;
        const float gx0 = std::floor(qx), gy0 = std::floor(qy);
        if (!Sane(gx0) || !Sane(gy0) ||
            !Readable(J, static_cast<int>(gx0), static_cast<int>(gy0), WP, w)) {
          if (level == 0) ok = false;
          break;
        }
        SampleBlock<WP>(J, static_cast<int>(gx0), static_cast<int>(gy0), qx - gx0, qy - gy0, w, warped);
        alignas(16) float b1c[WP] = {}, b2c[WP] = {};
        for (int r = 0; r < w; ++r) {
          const float* __restrict jr = warped + r * WP;
          const float* __restrict ir = inner + r * WP;
          const float* __restrict xr = gx + r * WP;
          const float* __restrict yr = gy + r * WP;
          for (int c = 0; c < WP; ++c) {
            const float d = jr[c] - ir[c];
            b1c[c] += d * xr[c];
            b2c[c] += d * yr[c];
          }
        }
        double b1 = 0.0, b2 = 0.0;
        for (int c = 0; c < WP; ++c) {
          b1 += b1c[c];
          b2 += b2c[c];
        }
        const cv::Point2f delta(static_cast<float>((a12 * b2 - a22 * b1) * inv_det),
                                static_cast<float>((a12 * b1 - a11 * b2) * inv_det));
        guess += delta;
        if (delta.dot(delta) <= eps2) break;
        // Oscillating between two positions: take the middle.
        if (it > 0 && std::abs(delta.x + prev_delta.x) < 0.01f && std::abs(delta.y + prev_delta.y) < 0.01f) {
          guess -= 0.5f * delta;
          break;
        }
        prev_delta = delta;
      }
    }
    (*next)[i] = guess;
    (*status)[i] = ok && std::isfinite(guess.x) && std::isfinite(guess.y) ? 1 : 0;
  }
}

}  // namespace

KltPyramid MakeKltPyramid(const std::vector<cv::Mat>& pyramid) {
  KltPyramid out;
  // With derivatives, cv::buildOpticalFlowPyramid interleaves [image, derivative] per level.
  const size_t stride = pyramid.size() > 1 && pyramid[1].type() != CV_8UC1 ? 2 : 1;
  for (size_t i = 0; i < pyramid.size(); i += stride) {
    const cv::Mat& m = pyramid[i];
    if (m.empty() || m.type() != CV_8UC1) break;
    // The whole buffer, border included, converted once: grey levels are exact in float,
    // so sampling the copy gives the bits sampling the bytes gave.
    cv::Size whole;
    cv::Point ofs;
    m.locateROI(whole, ofs);
    cv::Mat full = m;
    full.adjustROI(ofs.y, whole.height - ofs.y - m.rows, ofs.x, whole.width - ofs.x - m.cols);
    cv::Mat f;
    full.convertTo(f, CV_32F);
    out.levels.push_back(f(cv::Rect(ofs.x, ofs.y, m.cols, m.rows)));
  }
  return out;
}

void TrackPointsKlt(const KltPyramid& from, const KltPyramid& to, const std::vector<cv::Point2f>& pts,
                    std::vector<cv::Point2f>* next, std::vector<uint8_t>* status, const KltParams& params) {
  const size_t n = pts.size();
  status->assign(n, 0);
  next->resize(n);
  const std::vector<Level> lf = Levels(from), lt = Levels(to);
  const int w = params.window_px;
  if (lf.empty() || lt.empty() || w < 3 || w % 2 == 0 || w > kMaxKltWindow) return;
  const int top = std::min({params.max_level, static_cast<int>(lf.size()) - 1, static_cast<int>(lt.size()) - 1});
  switch ((w + 3) / 4) {
    case 1: TrackRange<4>(lf, lt, top, w, pts, next, status, params); break;
    case 2: TrackRange<8>(lf, lt, top, w, pts, next, status, params); break;
    case 3: TrackRange<12>(lf, lt, top, w, pts, next, status, params); break;
    case 4: TrackRange<16>(lf, lt, top, w, pts, next, status, params); break;
    case 5: TrackRange<20>(lf, lt, top, w, pts, next, status, params); break;
    case 6: TrackRange<24>(lf, lt, top, w, pts, next, status, params); break;
    case 7: TrackRange<28>(lf, lt, top, w, pts, next, status, params); break;
    case 8: TrackRange<32>(lf, lt, top, w, pts, next, status, params); break;
    default: TrackRange<kMaxKltWindow + 1>(lf, lt, top, w, pts, next, status, params); break;
  }
}

void TrackPointsKlt(const std::vector<cv::Mat>& from, const std::vector<cv::Mat>& to,
                    const std::vector<cv::Point2f>& pts, std::vector<cv::Point2f>* next,
                    std::vector<uint8_t>* status, const KltParams& params) {
  TrackPointsKlt(MakeKltPyramid(from), MakeKltPyramid(to), pts, next, status, params);
}

}  // namespace mbslam
