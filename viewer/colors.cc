#include "viewer/colors.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace mbslam {
namespace viewer {

Rgb ObjectColor(int id) {
  static constexpr std::array<Rgb, kObjectPaletteSize> kPalette = {{
      {255, 130, 0},    // orange
      {30, 80, 255},    // blue
      {230, 60, 200},   // magenta
      {0, 180, 210},    // cyan
      {130, 50, 220},   // purple
      {255, 110, 150},  // pink
      {0, 120, 120},    // teal
      {20, 30, 140},    // navy
  }};
  const int k = ((id - 1) % kObjectPaletteSize + kObjectPaletteSize) % kObjectPaletteSize;
  return kPalette[static_cast<size_t>(k)];
}

// A piecewise-linear scale: slate grey (ground), teal, green, yellow, brown (high).
Rgb HeightColor(double t) {
  if (!std::isfinite(t)) t = 0.0;
  t = std::clamp(t, 0.0, 1.0);
  static constexpr std::array<std::array<double, 3>, 5> kStops = {{
      {125, 130, 150},  // ground level: slate grey
      {40, 160, 175},   // teal
      {110, 185, 80},   // green
      {225, 200, 50},   // yellow
      {185, 100, 40},   // high: brown (not the trajectory's red)
  }};
  const double x = t * (kStops.size() - 1);
  const size_t i = std::min(static_cast<size_t>(x), kStops.size() - 2);
  const double f = x - static_cast<double>(i);
  auto mix = [&](int c) {
    return static_cast<uint8_t>(std::lround(kStops[i][c] * (1.0 - f) + kStops[i + 1][c] * f));
  };
  return Rgb{mix(0), mix(1), mix(2)};
}

}  // namespace viewer
}  // namespace mbslam
