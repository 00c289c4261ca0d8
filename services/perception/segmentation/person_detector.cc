#include "services/perception/segmentation/person_detector.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace mbslam {

PersonDetector::PersonDetector(const PersonDetectorOptions& options) : options_(options) {
  hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
}

bool PersonDetector::Detect(const cv::Mat& gray, const cv::Rect& box) const {
  if (box.height < options_.min_box_height_px || box.width <= 0) return false;
  // The default detector window is 64x128 px with a person of ~96 px in it. The region
  // searched is the box grown by `padding`, and at least one window's shape around a
  // person of the box's height (a moving person's hull is narrower than the window).
  constexpr double kPersonInWindowPx = 96.0;
  const double want_w = std::max(box.width * (1.0 + 2.0 * options_.padding), box.height * (64.0 / kPersonInWindowPx) * 1.25);
  const double want_h = std::max(box.height * (1.0 + 2.0 * options_.padding), box.height * (128.0 / kPersonInWindowPx) * 1.15);
  const double cx = box.x + 0.5 * box.width, cy = box.y + 0.5 * box.height;
  cv::Rect roi(static_cast<int>(std::floor(cx - 0.5 * want_w)), static_cast<int>(std::floor(cy - 0.5 * want_h)),
               static_cast<int>(std::ceil(want_w)), static_cast<int>(std::ceil(want_h)));
  roi &= cv::Rect(0, 0, gray.cols, gray.rows);
  if (roi.width <= 0 || roi.height <= 0) return false;
  cv::Mat patch = gray(roi);
  // Scale: a small person up to the window's person height (HOG only searches larger
  // scales), a large one down to max_box_height_px (bounds the cost), and the region to
  // at least one window.
  double scale = 1.0;
  if (box.height < kPersonInWindowPx) {
    scale = kPersonInWindowPx / box.height;
  } else if (box.height > options_.max_box_height_px) {
    scale = static_cast<double>(options_.max_box_height_px) / box.height;
  }
  scale = std::max(scale, std::max(64.0 / patch.cols, 128.0 / patch.rows));
  if (scale != 1.0) {
    cv::resize(patch, patch, cv::Size(), scale, scale, scale > 1.0 ? cv::INTER_LINEAR : cv::INTER_AREA);
  }
  std::vector<cv::Rect> found;
  std::vector<double> weights;
  hog_.detectMultiScale(patch, found, weights, options_.hit_threshold, cv::Size(8, 8), cv::Size(0, 0),
                        options_.scale_step, 2.0);
  for (const cv::Rect& f : found) {
    const cv::Rect in_image(static_cast<int>(f.x / scale) + roi.x, static_cast<int>(f.y / scale) + roi.y,
                            static_cast<int>(f.width / scale), static_cast<int>(f.height / scale));
    const double inside = (in_image & box).area();
    if (in_image.area() > 0 && inside / in_image.area() >= options_.min_overlap) return true;
  }
  return false;
}

}  // namespace mbslam
