#ifndef MBSLAM_TOOLS_SIM_PROCEDURAL_TEXTURE_H_
#define MBSLAM_TOOLS_SIM_PROCEDURAL_TEXTURE_H_

// Procedural, non-repeating surface textures for the simulator. Every texture is built
// from multi-octave value noise (features at every scale, for KLT), random blobs and
// polygons with sharp corners at many sizes (for FAST), line features (cracks, seams,
// stripes) and a surface-specific layout (paving stones, windows, planks, ...). The same
// seed gives the same texture bit for bit.

#include <opencv2/core.hpp>

#include <cstdint>

namespace mbslam {
namespace sim {

enum class TextureStyle {
  kAsphalt,   // dark road surface: gravel speckles, cracks, repair patches, paint marks
  kGrass,     // green ground cover with blades and dirt patches
  kPaving,    // irregular (Voronoi) paving stones with joints
  kFacade,    // building wall: plaster, irregular windows, stains, posters
  kConcrete,  // grey concrete: pores, stains, formwork seams
  kVehicle,   // painted body: livery stripes, decals, dark glass regions, dirt
  kClothing,  // fabric: coloured patches, stripes, folds
  kCrate,     // wooden planks: grain, knots, stencils
};

const char* TextureStyleName(TextureStyle style);

// A width x height BGR texture (CV_8UC3) of the given style for a surface where one
// texel covers `texel_m` metres (features such as windows or stones get their physical
// size). `tint` (BGR, each in [0, 1]) sets the base colour for the styles that have one
// (vehicle, clothing, facade); a negative tint picks one from the seed.
cv::Mat MakeTexture(TextureStyle style, int width, int height, double texel_m, uint64_t seed,
                    const cv::Scalar& tint = cv::Scalar(-1, -1, -1));

// Zero-mean, unit-variance multi-octave value noise (CV_32FC1): octave k has cells of
// `largest_cell_px / 2^k` pixels and amplitude `persistence^k`.
cv::Mat FractalNoise(int width, int height, uint64_t seed, double largest_cell_px, int octaves,
                     double persistence);

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_PROCEDURAL_TEXTURE_H_
