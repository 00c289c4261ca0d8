#ifndef MBSLAM_VIEWER_DRAW_UTIL_H_
#define MBSLAM_VIEWER_DRAW_UTIL_H_

// Text and legends drawn onto the snapshots with OpenCV (both views).

#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "viewer/colors.h"

namespace mbslam {
namespace viewer {

cv::Scalar ToBgr(const Rgb& color);

// Text whose baseline starts at `origin`, with a contrasting outline so it reads on any
// background. `scale` is OpenCV's font scale.
void DrawOutlinedText(cv::Mat* image, const std::string& text, cv::Point origin, double scale,
                      const Rgb& color, int thickness = 1);

struct LegendEntry {
  enum class Kind { kPoint, kLine, kBox };
  std::string label;
  Rgb color;
  Kind kind = Kind::kPoint;
};

// A legend box (entries one per line) with its top-left corner at `corner`.
void DrawLegend(cv::Mat* image, const std::vector<LegendEntry>& entries, cv::Point corner,
                double scale);

// Splits text at its "|" separators into lines no wider than max_width (px), as far as
// the pieces allow.
std::vector<std::string> WrapText(const std::string& text, int max_width, double scale);

// A dark band over the top of the image with the text (wrapped, see TextBand).
void DrawHeader(cv::Mat* image, const std::string& text, double scale);

// A dark band of the given width with the text in white, wrapped at its "|"
// separators when it is too long for one line.
cv::Mat TextBand(int width, const std::string& text, double scale);

// A light band of the given width with the legend's entries side by side (wrapped onto
// more rows when they do not fit).
cv::Mat LegendBand(int width, const std::vector<LegendEntry>& entries, double scale);

// Font scale that suits an image of this width (about 0.5 at 1280 px).
double FontScaleFor(int image_width);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_DRAW_UTIL_H_
