#pragma once
// Pyramidal Lucas-Kanade point tracking (Bouguet's formulation, thesis sec. 2.1): for each
// point, from the coarsest pyramid level down, the window around the point in the first
// image is the template; its gradient gives the 2x2 normal matrix once per level, and
// Gauss-Newton steps move the window in the second image until the step is below epsilon.
//
// The same algorithm as OpenCV's calcOpticalFlowPyrLK, at about half its cost (52 % of its
// instructions in frontend_bench): the window sits at one sub-pixel offset, so bilinear
// sampling is a 2x2 filter with constant weights over contiguous rows, and the row loops
// run over a compile-time width (the window rounded up to 4, the extra columns weighted
// zero), so they vectorise without remainders. The template's gradient is Scharr's
// derivative of the sampled template (one pixel wider) - the same as sampling a Scharr
// derivative image, as OpenCV does, since both are linear filters - so no derivative
// pyramid is needed. Results differ from OpenCV's in the last bits (its fixed point);
// the accuracy is the same (klt_test).

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace mbslam {

constexpr int kMaxKltWindow = 63;  // largest window side (px)

struct KltParams {
  int window_px = 15;          // window side (px, odd)
  int max_level = 2;           // coarsest pyramid level used (0 = the image only)
  int max_iterations = 12;     // Gauss-Newton steps per level (count)
  double epsilon_px = 0.05;    // a step below this ends the level (px)
  // A window whose normal matrix' smaller eigenvalue, per pixel, is below this is
  // untrackable (flat or a straight edge): ((grey levels / px)^2). OpenCV's default
  // minEigThreshold 1e-4 corresponds to about 0.1.
  double min_eigen = 0.1;
};

// Tracks `pts` from the pyramid `from` to the pyramid `to` (as built by
// cv::buildOpticalFlowPyramid, with or without derivative levels, CV_8UC1 images with
// the border it adds). `next` holds the initial guesses (level-0 pixels) and receives the
// results; `status` is 1 where a point was tracked. Points are independent: tracking a
// subset gives the same result for it.
void TrackPointsKlt(const std::vector<cv::Mat>& from, const std::vector<cv::Mat>& to,
                    const std::vector<cv::Point2f>& pts, std::vector<cv::Point2f>* next,
                    std::vector<uint8_t>* status, const KltParams& params);

}  // namespace mbslam
