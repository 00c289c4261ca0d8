#include "viewer/draw_util.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace mbslam {
namespace viewer {

cv::Scalar ToBgr(const Rgb& color) { return cv::Scalar(color.b, color.g, color.r); }

namespace {

void DrawSwatch(cv::Mat* image, const LegendEntry& e, cv::Point s0, cv::Point s1) {
  const cv::Point mid((s0.x + s1.x) / 2, (s0.y + s1.y) / 2);
  switch (e.kind) {
    case LegendEntry::Kind::kPoint:
      cv::circle(*image, mid, std::max(2, (s1.x - s0.x) / 4), ToBgr(e.color), cv::FILLED,
                 cv::LINE_AA);
      break;
    case LegendEntry::Kind::kLine:
      cv::line(*image, cv::Point(s0.x, mid.y), cv::Point(s1.x, mid.y), ToBgr(e.color), 3,
               cv::LINE_AA);
      break;
    case LegendEntry::Kind::kBox:
      cv::rectangle(*image, s0, s1, ToBgr(e.color), cv::FILLED);
      break;
  }
}

}  // namespace

std::vector<std::string> WrapText(const std::string& text, int max_width, double scale) {
  // Pieces end at "|" separators; lines are filled greedily.
  std::vector<std::string> pieces;
  size_t start = 0;
  while (start < text.size()) {
    const size_t bar = text.find('|', start);
    const size_t end = bar == std::string::npos ? text.size() : bar + 1;
    pieces.push_back(text.substr(start, end - start));
    start = end;
  }
  std::vector<std::string> lines;
  int baseline = 0;
  for (const std::string& piece : pieces) {
    const std::string candidate = lines.empty() ? piece : lines.back() + piece;
    if (!lines.empty() &&
        cv::getTextSize(candidate, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width <=
            max_width) {
      lines.back() = candidate;
    } else {
      const size_t first = piece.find_first_not_of(' ');  // a new line starts without blanks
      lines.push_back(first == std::string::npos ? piece : piece.substr(first));
    }
  }
  if (lines.empty()) lines.push_back("");
  return lines;
}

void DrawOutlinedText(cv::Mat* image, const std::string& text, cv::Point origin, double scale,
                      const Rgb& color, int thickness) {
  const int luminance = (299 * color.r + 587 * color.g + 114 * color.b) / 1000;
  const cv::Scalar outline = luminance > 140 ? cv::Scalar(0, 0, 0) : cv::Scalar(255, 255, 255);
  cv::putText(*image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, outline, thickness + 2,
              cv::LINE_AA);
  cv::putText(*image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, ToBgr(color), thickness,
              cv::LINE_AA);
}

void DrawLegend(cv::Mat* image, const std::vector<LegendEntry>& entries, cv::Point corner,
                double scale) {
  if (entries.empty()) return;
  int baseline = 0;
  const cv::Size m = cv::getTextSize("Mg", cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const int line = m.height + baseline + 4;
  const int swatch = m.height + 2;
  int width = 0;
  for (const auto& e : entries) {
    width = std::max(width,
                     cv::getTextSize(e.label, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width);
  }
  const cv::Rect box(corner.x, corner.y, width + swatch + 18,
                     line * static_cast<int>(entries.size()) + 8);
  const cv::Rect clipped = box & cv::Rect(0, 0, image->cols, image->rows);
  if (clipped.area() > 0) {
    cv::Mat roi = (*image)(clipped);
    cv::Mat white(roi.size(), roi.type(), cv::Scalar(255, 255, 255));
    cv::addWeighted(roi, 0.25, white, 0.75, 0.0, roi);
    cv::rectangle(*image, clipped, cv::Scalar(160, 160, 160), 1);
  }
  for (size_t i = 0; i < entries.size(); ++i) {
    const LegendEntry& e = entries[i];
    const int y = corner.y + 4 + static_cast<int>(i) * line;
    const cv::Point s0(corner.x + 6, y + 2), s1(corner.x + 6 + swatch, y + 2 + swatch);
    DrawSwatch(image, e, s0, s1);
    cv::putText(*image, e.label, cv::Point(s1.x + 8, y + m.height + 3), cv::FONT_HERSHEY_SIMPLEX,
                scale, cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
  }
}

void DrawHeader(cv::Mat* image, const std::string& text, double scale) {
  const cv::Mat band = TextBand(image->cols, text, scale);
  const cv::Rect rect(0, 0, image->cols, std::min(image->rows, band.rows));
  cv::Mat roi = (*image)(rect);
  cv::addWeighted(roi, 0.25, band(cv::Rect(0, 0, rect.width, rect.height)), 0.75, 0.0, roi);
}

cv::Mat TextBand(int width, const std::string& text, double scale) {
  int baseline = 0;
  const cv::Size m = cv::getTextSize("Mg", cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const std::vector<std::string> lines = WrapText(text, std::max(1, width - 12), scale);
  const int line_height = m.height + baseline + 4;
  cv::Mat band(static_cast<int>(lines.size()) * line_height + 6, std::max(1, width), CV_8UC3,
               cv::Scalar(40, 40, 40));
  for (size_t i = 0; i < lines.size(); ++i) {
    cv::putText(band, lines[i], cv::Point(6, 3 + m.height + static_cast<int>(i) * line_height),
                cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return band;
}

cv::Mat LegendBand(int width, const std::vector<LegendEntry>& entries, double scale) {
  int baseline = 0;
  const cv::Size m = cv::getTextSize("Mg", cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const int row_height = m.height + baseline + 10, swatch = m.height + 2;
  // Lay out first to know the number of rows.
  std::vector<cv::Point> at;
  int x = 6, row = 0;
  for (const auto& e : entries) {
    const int w = swatch + 6 +
                  cv::getTextSize(e.label, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width +
                  18;
    if (x > 6 && x + w > width) {
      x = 6;
      ++row;
    }
    at.emplace_back(x, row * row_height);
    x += w;
  }
  cv::Mat band((row + 1) * row_height, std::max(1, width), CV_8UC3, cv::Scalar(245, 245, 245));
  for (size_t i = 0; i < entries.size(); ++i) {
    const cv::Point s0(at[i].x, at[i].y + 5), s1(at[i].x + swatch, at[i].y + 5 + swatch);
    DrawSwatch(&band, entries[i], s0, s1);
    cv::putText(band, entries[i].label, cv::Point(s1.x + 6, at[i].y + 5 + m.height),
                cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(20, 20, 20), 1, cv::LINE_AA);
  }
  return band;
}

double FontScaleFor(int image_width) { return std::clamp(image_width / 2200.0, 0.35, 1.2); }

}  // namespace viewer
}  // namespace mbslam
