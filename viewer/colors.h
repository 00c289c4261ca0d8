#ifndef MBSLAM_VIEWER_COLORS_H_
#define MBSLAM_VIEWER_COLORS_H_

// The viewer's legend (after Kundu 2011, fig. 6.1): static points coloured by height
// above the ground plane, camera trajectory red, each moving object in its own colour,
// bearing-only particles green. In the image view: static tracks green, moving red,
// unassigned yellow, occluded blue, hulls shaded in their object's colour.

#include <cstdint>

namespace mbslam {
namespace viewer {

struct Rgb {
  uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
};

// 3D view.
constexpr Rgb kCameraTrajectoryColor{220, 20, 20};  // red
constexpr Rgb kCurrentCameraColor{200, 0, 0};       // red, thicker frustum
constexpr Rgb kKeyframeColor{80, 80, 80};           // dark grey
constexpr Rgb kParticleColor{0, 190, 0};            // green
constexpr Rgb kGridColor{200, 200, 200};            // light grey

// Image view.
constexpr Rgb kStaticTrackColor{0, 220, 0};        // green
constexpr Rgb kMovingTrackColor{255, 30, 30};      // red
constexpr Rgb kUnassignedTrackColor{255, 230, 0};  // yellow
constexpr Rgb kOccludedTrackColor{0, 150, 255};    // blue (lighter than object blue)
constexpr Rgb kEpipolarLineColor{255, 0, 255};     // magenta

// Colour of moving object `id` (> 0): a fixed palette of saturated colours that are
// not the camera's red nor the particles' green, repeating every kObjectPaletteSize ids.
Rgb ObjectColor(int id);
constexpr int kObjectPaletteSize = 8;

// Height colour scale (slate grey at the ground -> teal -> green -> yellow -> brown high), t in [0,
// 1] (clamped).
Rgb HeightColor(double t);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_COLORS_H_
