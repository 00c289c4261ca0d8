#include "tools/sim/procedural_texture.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace mbslam {
namespace sim {
namespace {

class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double Uniform(double a, double b) {
    return std::uniform_real_distribution<double>(a, b)(engine_);
  }
  // Log-uniform in [a, b] (a, b > 0): as many small features as large ones per octave.
  double LogUniform(double a, double b) { return std::exp(Uniform(std::log(a), std::log(b))); }
  double Normal(double sigma) { return std::normal_distribution<double>(0.0, sigma)(engine_); }
  int Int(int a, int b) { return std::uniform_int_distribution<int>(a, b)(engine_); }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }
  uint64_t Next() { return engine_(); }

 private:
  std::mt19937_64 engine_;
};

cv::Scalar Clamp01(const cv::Scalar& c) {
  cv::Scalar out;
  for (int i = 0; i < 3; ++i) {
    out[i] = std::clamp(c[i], 0.0, 1.0);
  }
  out[3] = 0.0;
  return out;
}

// A colour near `base` (BGR in [0,1]) with brightness factor in [lo, hi] and hue jitter.
cv::Scalar Vary(Rng* rng, const cv::Scalar& base, double lo, double hi, double jitter) {
  const double k = rng->Uniform(lo, hi);
  cv::Scalar c;
  for (int i = 0; i < 3; ++i) {
    c[i] = base[i] * k + rng->Normal(jitter);
  }
  return Clamp01(c);
}

cv::Scalar Gray(double v) { return cv::Scalar(v, v, v); }

// One of a few natural base colours (BGR), brightness-varied, with a slight hue jitter.
cv::Scalar FromPalette(Rng* rng, const std::vector<cv::Scalar>& palette, double lo, double hi) {
  return Vary(rng, palette[static_cast<size_t>(rng->Int(0, static_cast<int>(palette.size()) - 1))],
              lo, hi, 0.015);
}

const std::vector<cv::Scalar> kStonePalette = {
    {0.55, 0.57, 0.58},  // grey granite
    {0.45, 0.55, 0.65},  // beige sandstone
    {0.35, 0.40, 0.60},  // red brick paver
    {0.50, 0.50, 0.48},  // concrete
};
const std::vector<cv::Scalar> kFacadePalette = {
    {0.62, 0.70, 0.78},  // cream plaster
    {0.55, 0.56, 0.57},  // grey render
    {0.30, 0.35, 0.62},  // brick
    {0.78, 0.80, 0.80},  // white
    {0.45, 0.65, 0.75},  // ochre
    {0.60, 0.55, 0.45},  // blue-grey
};

cv::Scalar RandomSaturated(Rng* rng) {
  // A random fairly saturated colour, built in HSV.
  cv::Mat hsv(
      1, 1, CV_32FC3,
      cv::Scalar(rng->Uniform(0.0, 360.0), rng->Uniform(0.4, 0.9), rng->Uniform(0.35, 0.95)));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3f v = bgr.at<cv::Vec3f>(0, 0);
  return cv::Scalar(v[0], v[1], v[2]);
}

// Multiplies every channel by (1 + amount * noise).
void Modulate(cv::Mat* img, const cv::Mat& noise, double amount) {
  cv::Mat factor = 1.0 + amount * noise;
  factor = cv::max(factor, 0.0);
  cv::Mat channels[3];
  cv::split(*img, channels);
  for (auto& c : channels) {
    c = c.mul(factor);
  }
  cv::merge(channels, 3, *img);
}

std::vector<cv::Point> IrregularPolygon(Rng* rng, cv::Point2d center, double radius) {
  const int n = rng->Int(3, 8);
  std::vector<double> angles;
  angles.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    angles.push_back(rng->Uniform(0.0, 2.0 * M_PI));
  }
  std::sort(angles.begin(), angles.end());
  std::vector<cv::Point> pts;
  for (double a : angles) {
    const double r = radius * rng->Uniform(0.45, 1.0);
    pts.emplace_back(cvRound(center.x + r * std::cos(a)), cvRound(center.y + r * std::sin(a)));
  }
  return pts;
}

// Random shapes (ellipses, polygons, rotated rectangles) with sizes log-uniform in
// [min_px, max_px]; colours from `color`.
template <typename ColorFn>
void DrawBlobs(cv::Mat* img, Rng* rng, int count, double min_px, double max_px, ColorFn color) {
  if (max_px < min_px) {
    max_px = min_px;
  }
  for (int i = 0; i < count; ++i) {
    const cv::Point2d c(rng->Uniform(-max_px, img->cols + max_px),
                        rng->Uniform(-max_px, img->rows + max_px));
    const double r = rng->LogUniform(std::max(0.75, min_px), std::max(1.0, max_px));
    const cv::Scalar col = color(rng);
    const int type = rng->Int(0, 2);
    if (type == 0) {
      const cv::Size axes(std::max(1, cvRound(r)),
                          std::max(1, cvRound(r * rng->Uniform(0.3, 1.0))));
      cv::ellipse(*img, cv::Point(cvRound(c.x), cvRound(c.y)), axes, rng->Uniform(0.0, 180.0), 0.0,
                  360.0, col, cv::FILLED);
    } else if (type == 1) {
      const std::vector<std::vector<cv::Point>> poly{IrregularPolygon(rng, c, r)};
      cv::fillPoly(*img, poly, col);
    } else {
      const cv::RotatedRect rect(
          cv::Point2f(static_cast<float>(c.x), static_cast<float>(c.y)),
          cv::Size2f(static_cast<float>(2 * r), static_cast<float>(2 * r * rng->Uniform(0.2, 1.0))),
          static_cast<float>(rng->Uniform(0.0, 180.0)));
      cv::Point2f corners[4];
      rect.points(corners);
      std::vector<cv::Point> pts;
      for (const auto& p : corners) {
        pts.emplace_back(cvRound(p.x), cvRound(p.y));
      }
      cv::fillConvexPoly(*img, pts, col);
    }
  }
}

// Random-walk polylines (cracks, scratches, seams).
template <typename ColorFn>
void DrawCracks(cv::Mat* img, Rng* rng, int count, double min_len_px, double max_len_px,
                int max_thickness, ColorFn color) {
  for (int i = 0; i < count; ++i) {
    cv::Point2d p(rng->Uniform(0, img->cols), rng->Uniform(0, img->rows));
    double heading = rng->Uniform(0.0, 2.0 * M_PI);
    const double len = rng->LogUniform(std::max(1.0, min_len_px), std::max(2.0, max_len_px));
    const int segments = rng->Int(2, 8);
    std::vector<cv::Point> pts{cv::Point(cvRound(p.x), cvRound(p.y))};
    for (int s = 0; s < segments; ++s) {
      heading += rng->Normal(0.6);
      p += cv::Point2d(std::cos(heading), std::sin(heading)) * (len / segments);
      pts.emplace_back(cvRound(p.x), cvRound(p.y));
    }
    cv::polylines(*img, std::vector<std::vector<cv::Point>>{pts}, false, color(rng),
                  rng->Int(1, std::max(1, max_thickness)));
  }
}

int CountFor(const cv::Mat& img, double per_megapixel) {
  return std::max(1, static_cast<int>(per_megapixel * img.total() / 1e6));
}

// Irregular stones: Voronoi cells of random sites, each with its own shade, dark joints.
void DrawVoronoiStones(cv::Mat* img, Rng* rng, double stone_px, const cv::Scalar& base,
                       double joint_px) {
  const cv::Rect2f bounds(
      -2.0f * static_cast<float>(stone_px), -2.0f * static_cast<float>(stone_px),
      static_cast<float>(img->cols + 4 * stone_px), static_cast<float>(img->rows + 4 * stone_px));
  cv::Subdiv2D subdiv(
      cv::Rect(cvFloor(bounds.x), cvFloor(bounds.y), cvCeil(bounds.width), cvCeil(bounds.height)));
  const int n = std::max(4, static_cast<int>(bounds.area() / (stone_px * stone_px)));
  for (int i = 0; i < n; ++i) {
    subdiv.insert(
        cv::Point2f(static_cast<float>(rng->Uniform(bounds.x + 1, bounds.x + bounds.width - 1)),
                    static_cast<float>(rng->Uniform(bounds.y + 1, bounds.y + bounds.height - 1))));
  }
  std::vector<std::vector<cv::Point2f>> facets;
  std::vector<cv::Point2f> centers;
  subdiv.getVoronoiFacetList(std::vector<int>(), facets, centers);
  const int joint = std::max(1, cvRound(joint_px));
  for (const auto& f : facets) {
    std::vector<cv::Point> poly;
    poly.reserve(f.size());
    for (const auto& p : f) {
      poly.emplace_back(cvRound(p.x), cvRound(p.y));
    }
    cv::fillConvexPoly(*img, poly, Vary(rng, base, 0.6, 1.35, 0.015));
    cv::polylines(*img, std::vector<std::vector<cv::Point>>{poly}, true,
                  base * rng->Uniform(0.25, 0.45), joint);
  }
}

}  // namespace

const char* TextureStyleName(TextureStyle style) {
  switch (style) {
    case TextureStyle::kAsphalt:
      return "asphalt";
    case TextureStyle::kGrass:
      return "grass";
    case TextureStyle::kPaving:
      return "paving";
    case TextureStyle::kFacade:
      return "facade";
    case TextureStyle::kConcrete:
      return "concrete";
    case TextureStyle::kVehicle:
      return "vehicle";
    case TextureStyle::kClothing:
      return "clothing";
    case TextureStyle::kCrate:
      return "crate";
  }
  return "unknown";
}

cv::Mat FractalNoise(int width, int height, uint64_t seed, double largest_cell_px, int octaves,
                     double persistence) {
  Rng rng(seed);
  cv::Mat sum(height, width, CV_32F, cv::Scalar(0));
  double amplitude = 1.0;
  double cell = std::max(1.0, largest_cell_px);
  for (int k = 0; k < octaves && cell >= 1.0; ++k) {
    if (cell < 1.5) {  // finer than the pixels: white noise
      cv::Mat white(height, width, CV_32F);
      cv::RNG cv_rng(rng.Next());
      cv_rng.fill(white, cv::RNG::NORMAL, 0.0, 1.0);
      sum += amplitude * white;
    } else {
      const int gw = static_cast<int>(std::ceil(width / cell)) + 3;
      const int gh = static_cast<int>(std::ceil(height / cell)) + 3;
      cv::Mat grid(gh, gw, CV_32F);
      for (int r = 0; r < gh; ++r) {
        for (int c = 0; c < gw; ++c) {
          grid.at<float>(r, c) = static_cast<float>(rng.Normal(1.0));
        }
      }
      // Smooth (bicubic) upsampling of the random grid, cropped at a random sub-cell
      // offset so that octaves do not share their cell boundaries.
      cv::Mat up;
      cv::resize(grid, up, cv::Size(cvRound(gw * cell), cvRound(gh * cell)), 0, 0, cv::INTER_CUBIC);
      const int ox = static_cast<int>(rng.Uniform(cell, 2.0 * cell));
      const int oy = static_cast<int>(rng.Uniform(cell, 2.0 * cell));
      sum += amplitude * up(cv::Rect(std::min(ox, up.cols - width), std::min(oy, up.rows - height),
                                     width, height));
    }
    amplitude *= persistence;
    cell *= 0.5;
  }
  cv::Scalar mean, stddev;
  cv::meanStdDev(sum, mean, stddev);
  sum = (sum - mean[0]) / std::max(1e-6, stddev[0]);
  return sum;
}

cv::Mat MakeTexture(TextureStyle style, int width, int height, double texel_m, uint64_t seed,
                    const cv::Scalar& tint) {
  width = std::max(8, width);
  height = std::max(8, height);
  texel_m = std::max(1e-4, texel_m);
  Rng rng(seed * 0x9E3779B97F4A7C15ULL + static_cast<uint64_t>(style) + 1);
  const double px_per_m = 1.0 / texel_m;
  auto px = [&](double metres) { return metres * px_per_m; };
  const double max_dim = std::max(width, height);
  const bool have_tint = tint[0] >= 0.0;

  cv::Mat img(height, width, CV_32FC3);
  const cv::Mat low = FractalNoise(width, height, rng.Next(), std::min(px(2.0), max_dim), 4, 0.6);
  const cv::Mat grain =
      FractalNoise(width, height, rng.Next(), std::min(px(0.08), max_dim), 5, 0.7);

  switch (style) {
    case TextureStyle::kAsphalt: {
      const cv::Scalar base = Gray(rng.Uniform(0.28, 0.4));
      img.setTo(base);
      Modulate(&img, low, 0.18);
      // Repair patches and wet stains.
      DrawBlobs(&img, &rng, CountFor(img, 12), px(0.3), px(1.5),
                [&](Rng* r) { return Vary(r, base, 0.6, 1.4, 0.01); });
      // Gravel: many small light and dark stones.
      DrawBlobs(&img, &rng, CountFor(img, 9000), 1.0, std::max(1.5, px(0.025)), [&](Rng* r) {
        return Gray(r->Chance(0.5) ? r->Uniform(0.05, 0.2) : r->Uniform(0.5, 0.8));
      });
      // Faded paint marks.
      DrawBlobs(&img, &rng, CountFor(img, 3), px(0.1), px(0.6), [&](Rng* r) {
        return r->Chance(0.7) ? Gray(r->Uniform(0.7, 0.9)) : cv::Scalar(0.2, 0.75, 0.85);
      });
      DrawCracks(&img, &rng, CountFor(img, 60), px(0.2), px(2.0), 2,
                 [&](Rng* r) { return Gray(r->Uniform(0.05, 0.15)); });
      Modulate(&img, grain, 0.25);
      break;
    }
    case TextureStyle::kGrass: {
      const cv::Scalar base(0.12, 0.45, 0.25);
      img.setTo(base);
      Modulate(&img, low, 0.3);
      DrawBlobs(&img, &rng, CountFor(img, 25), px(0.1), px(0.9), [&](Rng* r) {
        return Vary(r, cv::Scalar(0.2, 0.35, 0.45), 0.6, 1.3, 0.03);
      });  // dirt
      DrawCracks(&img, &rng, CountFor(img, 6000), 2.0, std::max(3.0, px(0.08)), 1,
                 [&](Rng* r) { return Vary(r, base, 0.4, 1.8, 0.04); });  // blades
      DrawBlobs(&img, &rng, CountFor(img, 800), 1.0, std::max(1.5, px(0.03)), [&](Rng* r) {
        return r->Chance(0.2) ? cv::Scalar(0.2, 0.85, 0.9) : Vary(r, base, 0.3, 1.6, 0.05);
      });
      Modulate(&img, grain, 0.3);
      break;
    }
    case TextureStyle::kPaving: {
      const cv::Scalar base = FromPalette(&rng, kStonePalette, 0.8, 1.2);
      img.setTo(base);
      DrawVoronoiStones(&img, &rng, px(rng.Uniform(0.25, 0.45)), base, std::max(1.0, px(0.012)));
      Modulate(&img, low, 0.15);
      DrawBlobs(&img, &rng, CountFor(img, 3000), 1.0, std::max(1.5, px(0.02)),
                [&](Rng* r) { return Vary(r, base, 0.3, 1.5, 0.01); });
      DrawBlobs(&img, &rng, CountFor(img, 15), px(0.2), px(1.0),
                [&](Rng* r) { return Vary(r, base, 0.5, 0.8, 0.01); });  // stains
      Modulate(&img, grain, 0.2);
      break;
    }
    case TextureStyle::kFacade: {
      const cv::Scalar base =
          have_tint ? Clamp01(tint) : FromPalette(&rng, kFacadePalette, 0.8, 1.15);
      img.setTo(base);
      Modulate(&img, low, 0.15);
      // Irregular windows: floors of varying height, windows of varying width and spacing.
      double y = px(rng.Uniform(0.3, 1.5));
      while (y < height) {
        const double floor_h = px(rng.Uniform(2.6, 3.6));
        const double win_h = floor_h * rng.Uniform(0.4, 0.65);
        double x = px(rng.Uniform(0.2, 1.5));
        while (x < width) {
          const double win_w = px(rng.Uniform(0.6, 2.2));
          if (rng.Chance(0.85)) {
            const cv::Rect r(cvRound(x), cvRound(y), cvRound(win_w), cvRound(win_h));
            cv::rectangle(img, r, Vary(&rng, base, 0.4, 0.6, 0.02), cv::FILLED);  // frame
            const int f = std::max(1, cvRound(px(0.06)));
            const cv::Rect glass(r.x + f, r.y + f, std::max(1, r.width - 2 * f),
                                 std::max(1, r.height - 2 * f));
            cv::rectangle(img, glass, Vary(&rng, cv::Scalar(0.45, 0.35, 0.25), 0.4, 1.4, 0.05),
                          cv::FILLED);
            // Reflections / curtains inside the glass.
            cv::Mat roi = img(glass & cv::Rect(0, 0, width, height));
            if (!roi.empty()) {
              DrawBlobs(&roi, &rng, rng.Int(1, 4), std::max(1.0, glass.width * 0.1),
                        std::max(2.0, glass.width * 0.5), [&](Rng* r) {
                          return Vary(r, cv::Scalar(0.6, 0.55, 0.5), 0.3, 1.6, 0.08);
                        });
            }
            if (rng.Chance(0.5)) {  // mullion
              cv::line(img, cv::Point(r.x + r.width / 2, r.y),
                       cv::Point(r.x + r.width / 2, r.y + r.height),
                       Vary(&rng, base, 0.4, 0.6, 0.02), f);
            }
          }
          x += win_w + px(rng.Uniform(0.5, 2.5));
        }
        y += floor_h;
      }
      DrawBlobs(&img, &rng, CountFor(img, 40), px(0.1), px(1.2), [&](Rng* r) {
        return r->Chance(0.3) ? RandomSaturated(r) : Vary(r, base, 0.55, 1.3, 0.03);
      });
      DrawBlobs(&img, &rng, CountFor(img, 2500), 1.0, std::max(1.5, px(0.03)),
                [&](Rng* r) { return Vary(r, base, 0.4, 1.5, 0.03); });
      DrawCracks(&img, &rng, CountFor(img, 40), px(0.2), px(2.5), 2,
                 [&](Rng* r) { return Vary(r, base, 0.3, 0.5, 0.02); });
      Modulate(&img, grain, 0.18);
      break;
    }
    case TextureStyle::kConcrete: {
      const cv::Scalar base = Vary(&rng, Gray(0.6), 0.75, 1.2, 0.03);
      img.setTo(base);
      Modulate(&img, low, 0.2);
      // Formwork seams at irregular spacing.
      double x = px(rng.Uniform(0.2, 1.0));
      while (x < width) {
        cv::line(img, cv::Point(cvRound(x), 0),
                 cv::Point(cvRound(x + rng.Normal(px(0.05))), height),
                 Vary(&rng, base, 0.55, 0.75, 0.02), std::max(1, cvRound(px(0.01))));
        x += px(rng.Uniform(0.6, 1.6));
      }
      DrawBlobs(&img, &rng, CountFor(img, 30), px(0.05), px(0.6),
                [&](Rng* r) { return Vary(r, base, 0.6, 1.25, 0.04); });
      DrawBlobs(&img, &rng, CountFor(img, 5000), 1.0, std::max(1.5, px(0.015)),
                [&](Rng* r) { return Vary(r, base, 0.2, 0.6, 0.02); });  // pores
      DrawCracks(&img, &rng, CountFor(img, 80), px(0.05), px(0.8), 1,
                 [&](Rng* r) { return Vary(r, base, 0.3, 0.6, 0.02); });
      Modulate(&img, grain, 0.2);
      break;
    }
    case TextureStyle::kVehicle: {
      const cv::Scalar base = have_tint ? Clamp01(tint) : RandomSaturated(&rng);
      img.setTo(base);
      Modulate(&img, low, 0.2);
      // Dark glass regions, livery stripes and decals.
      DrawBlobs(&img, &rng, CountFor(img, 25), px(0.15), px(0.7),
                [&](Rng* r) { return Gray(r->Uniform(0.05, 0.25)); });
      for (int i = 0, n = rng.Int(2, 5); i < n; ++i) {
        const int y0 = rng.Int(0, height - 1);
        cv::line(img, cv::Point(0, y0), cv::Point(width, y0 + rng.Int(-height / 4, height / 4)),
                 RandomSaturated(&rng), std::max(1, cvRound(px(rng.Uniform(0.02, 0.15)))));
      }
      DrawBlobs(&img, &rng, CountFor(img, 80), px(0.03), px(0.35), [&](Rng* r) {
        return r->Chance(0.5) ? RandomSaturated(r) : Gray(r->Uniform(0.0, 1.0));
      });
      DrawBlobs(&img, &rng, CountFor(img, 6000), 1.0, std::max(1.5, px(0.025)), [&](Rng* r) {
        return Vary(r, cv::Scalar(0.3, 0.38, 0.45), 0.5, 1.5, 0.05);
      });  // dirt
      DrawCracks(&img, &rng, CountFor(img, 100), px(0.03), px(0.5), 1,
                 [&](Rng* r) { return Vary(r, base, 0.3, 1.7, 0.05); });  // scratches, panel gaps
      Modulate(&img, grain, 0.22);
      break;
    }
    case TextureStyle::kClothing: {
      const cv::Scalar base = have_tint ? Clamp01(tint) : RandomSaturated(&rng);
      const cv::Scalar second = RandomSaturated(&rng);
      img.setTo(base);
      Modulate(&img, low, 0.2);
      const double stripe = px(rng.Uniform(0.02, 0.08));
      const double angle = rng.Uniform(0.0, M_PI);
      const cv::Point2d dir(std::cos(angle), std::sin(angle));
      double s = -max_dim;
      while (s < 2 * max_dim) {
        const cv::Point2d n(-dir.y, dir.x);
        const cv::Point2d c = n * s;
        cv::line(img, c - dir * 2.0 * max_dim, c + dir * 2.0 * max_dim,
                 Vary(&rng, second, 0.7, 1.2, 0.05), std::max(1, cvRound(stripe)));
        s += stripe * rng.Uniform(2.0, 6.0);
      }
      DrawBlobs(&img, &rng, CountFor(img, 300), px(0.02), px(0.15), [&](Rng* r) {
        return r->Chance(0.5) ? RandomSaturated(r) : Vary(r, base, 0.3, 1.6, 0.05);
      });
      DrawCracks(&img, &rng, CountFor(img, 400), px(0.03), px(0.3), 2,
                 [&](Rng* r) { return Vary(r, base, 0.3, 0.6, 0.03); });  // folds, seams
      DrawBlobs(&img, &rng, CountFor(img, 4000), 1.0, std::max(1.5, px(0.01)),
                [&](Rng* r) { return Vary(r, base, 0.5, 1.5, 0.05); });
      Modulate(&img, grain, 0.2);
      break;
    }
    case TextureStyle::kCrate: {
      const cv::Scalar base = Vary(&rng, cv::Scalar(0.25, 0.45, 0.62), 0.7, 1.2, 0.04);
      img.setTo(base);
      // Planks of random widths with stretched grain.
      double y = 0.0;
      while (y < height) {
        const double h = px(rng.Uniform(0.08, 0.2));
        const cv::Rect r(0, cvRound(y), width, std::max(1, cvRound(h)));
        cv::rectangle(img, r, Vary(&rng, base, 0.75, 1.25, 0.03), cv::FILLED);
        cv::line(img, cv::Point(0, cvRound(y)), cv::Point(width, cvRound(y)), base * 0.35,
                 std::max(1, cvRound(px(0.008))));
        y += h;
      }
      cv::Mat streak = FractalNoise(std::max(8, width / 8), height, rng.Next(), px(0.05), 4, 0.6);
      cv::resize(streak, streak, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
      Modulate(&img, streak, 0.2);
      DrawBlobs(&img, &rng, CountFor(img, 150), 1.5, std::max(2.0, px(0.03)),
                [&](Rng* r) { return Vary(r, base, 0.3, 0.6, 0.03); });  // knots, nails
      DrawBlobs(&img, &rng, CountFor(img, 20), px(0.05), px(0.25), [&](Rng* r) {
        return r->Chance(0.5) ? Gray(0.1) : RandomSaturated(r);
      });  // stencils
      DrawCracks(&img, &rng, CountFor(img, 60), px(0.05), px(0.4), 1,
                 [&](Rng* r) { return Vary(r, base, 0.3, 0.6, 0.03); });
      Modulate(&img, grain, 0.15);
      break;
    }
  }
  // Soften texel-level aliasing of the drawn shapes.
  cv::GaussianBlur(img, img, cv::Size(0, 0), 0.6);
  cv::Mat out;
  img.convertTo(out, CV_8UC3, 255.0);
  return out;
}

}  // namespace sim
}  // namespace mbslam
