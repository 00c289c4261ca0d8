#ifndef MBSLAM_SERVICES_PERCEPTION_TRACKING_PATCH_MATCHER_H_
#define MBSLAM_SERVICES_PERCEPTION_TRACKING_PATCH_MATCHER_H_

// Zero-mean SSD patch matching (thesis sec. 2.2): finds a template in a search window
// around a predicted position, with sub-pixel refinement by a parabola fit.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace mbslam {

// Extracts a size x size patch centred at uv (bilinear). False near the border.
bool ExtractPatch(const cv::Mat& image, const Eigen::Vector2f& uv, int size, cv::Mat* patch);

// Normalised cross-correlation of two patches of the same size, in [-1, 1]; 0 when
// either is flat.
float PatchNcc(const cv::Mat& a, const cv::Mat& b);

// Cornerness of a patch: the smaller over the larger eigenvalue of its structure tensor
// (central differences over the interior), in [0, 1]; 0 for a flat or too small patch. An
// edge is near 0: a track on it can slide along it.
double PatchCornerRatio(const cv::Mat& patch);

struct PatchMatch {
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();  // best position (px)
  float score = 0.0f;   // mean squared zero-mean difference per pixel (gray levels^2)
  float second = 0.0f;  // best score outside the peak's neighbourhood (ambiguity check)
  bool found = false;
};

// Searches `patch` in `image` within +-radius px of `predicted`.
PatchMatch FindPatchZssd(const cv::Mat& image, const cv::Mat& patch, const Eigen::Vector2f& predicted,
                         int radius);

// Affine patch warps (thesis sec. 2.2). `reference` is a float (CV_32F) square patch
// of odd side centred on a feature in a reference image; `cur_from_ref` maps pixel
// offsets around the feature in that image to offsets in the current image. Fills
// `templ` (CV_32F, side x side) with the reference's appearance as the current image
// should show it. False when the warp is singular or needs samples outside `reference`.
bool WarpReferencePatch(const cv::Mat& reference, const Eigen::Matrix2f& cur_from_ref, int side, cv::Mat* templ);

struct PatchAlignment {
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();  // aligned position (px)
  float ncc = 0.0f;       // normalised cross-correlation there (inner pixels)
  int iterations = 0;
  bool converged = false;  // the last step was below the tolerance
};

// Translational Lucas-Kanade (inverse compositional) of a float template (CV_32F, odd
// side n >= 5) in an 8-bit image from `start`, the template's gain and bias free; the
// n-2 inner pixels are compared (the border gives the template's gradients).
PatchAlignment AlignPatch(const cv::Mat& image, const cv::Mat& templ, const Eigen::Vector2f& start,
                          int max_iterations = 10, float tolerance_px = 0.01f);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_TRACKING_PATCH_MATCHER_H_
