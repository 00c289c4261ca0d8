#pragma once
// Pyramidal Lucas-Kanade point tracking (Bouguet's formulation, thesis sec. 2.1): for each
// point, from the coarsest pyramid level down, the window around the point in the first
// image is the template; its gradient gives the 2x2 normal matrix once per level, and
// Gauss-Newton steps move the window in the second image until the step is below epsilon.
//
// The same algorithm as OpenCV's calcOpticalFlowPyrLK, at about a fifth of its
// instructions (frontend_bench under callgrind, 21 images: 428 M, the float conversion
// included, against 2,371 M): the window sits at one sub-pixel offset, so bilinear
// sampling is a 2x2 filter with constant weights over contiguous rows of floats (the
// pyramid converted once per image, KltPyramid), and the row loops run over a
// compile-time width (the window rounded up to 4, the extra columns weighted zero), so
// they vectorise without remainders. The template's gradient is Scharr's derivative of
// the sampled template (one pixel wider) - the same as sampling a Scharr derivative
// image, as OpenCV does, since both are linear filters - so no derivative pyramid is
// needed. Results differ from OpenCV's in the last bits (its fixed point); the accuracy
// is the same (klt_test).

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

// A pyramid as KLT reads it: each level's grey levels as floats (CV_32FC1), with the
// border of the pyramid it was made from (a view into the converted whole buffer).
// Converted once per image (about 0.5 M instructions at 640x480 with three levels and
// the border), it spares every KLT window its byte-to-float conversions: sampling the
// bytes was 60 % of KLT's instructions, each pixel converted four times per iteration
// (866 M -> 444 M instructions in frontend_bench, the same results bit for bit).
struct KltPyramid {
  std::vector<cv::Mat> levels;
  bool empty() const { return levels.empty(); }
};

// From a pyramid built by cv::buildOpticalFlowPyramid (CV_8UC1 levels with the border it
// adds; derivative levels, if any, are skipped).
KltPyramid MakeKltPyramid(const std::vector<cv::Mat>& pyramid);

// Tracks `pts` from the pyramid `from` to the pyramid `to`. `next` holds the initial
// guesses (level-0 pixels) and receives the results; `status` is 1 where a point was
// tracked. Points are independent: tracking a subset gives the same result for it.
void TrackPointsKlt(const KltPyramid& from, const KltPyramid& to, const std::vector<cv::Point2f>& pts,
                    std::vector<cv::Point2f>* next, std::vector<uint8_t>* status, const KltParams& params);

// The same from cv::buildOpticalFlowPyramid's pyramids, converted for this call.
void TrackPointsKlt(const std::vector<cv::Mat>& from, const std::vector<cv::Mat>& to,
                    const std::vector<cv::Point2f>& pts, std::vector<cv::Point2f>* next,
                    std::vector<uint8_t>* status, const KltParams& params);

}  // namespace mbslam
