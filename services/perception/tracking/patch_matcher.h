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

struct PatchMatch {
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();  // best position (px)
  float score = 0.0f;   // mean squared zero-mean difference per pixel (gray levels^2)
  float second = 0.0f;  // best score outside the peak's neighbourhood (ambiguity check)
  bool found = false;
};

// Searches `patch` in `image` within +-radius px of `predicted`.
PatchMatch FindPatchZssd(const cv::Mat& image, const cv::Mat& patch, const Eigen::Vector2f& predicted,
                         int radius);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_TRACKING_PATCH_MATCHER_H_
