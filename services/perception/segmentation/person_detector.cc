#include "services/perception/segmentation/person_detector.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

namespace mbslam {

PersonDetector::PersonDetector(const PersonDetectorOptions& options) : options_(options) {
  hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
}

bool PersonDetector::Detect(const cv::Mat& gray, const cv::Rect& box) const {
  if (box.height < options_.min_box_height_px) return false;
  const int px = static_cast<int>(box.width * options_.padding);
  const int py = static_cast<int>(box.height * options_.padding);
  cv::Rect roi(box.x - px, box.y - py, box.width + 2 * px, box.height + 2 * py);
  roi &= cv::Rect(0, 0, gray.cols, gray.rows);
  if (roi.width < 64 || roi.height < 128) {
    // The default detector window is 64x128: upscale small regions to it.
    if (roi.width <= 0 || roi.height <= 0) return false;
  }
  cv::Mat patch = gray(roi);
  double scale = 1.0;
  if (patch.cols < 64 || patch.rows < 128) {
    scale = std::max(64.0 / patch.cols, 128.0 / patch.rows);
    cv::resize(patch, patch, cv::Size(), scale, scale, cv::INTER_LINEAR);
  }
  std::vector<cv::Rect> found;
  std::vector<double> weights;
  hog_.detectMultiScale(patch, found, weights, options_.hit_threshold, cv::Size(8, 8), cv::Size(0, 0),
                        1.05, 2.0);
  for (const cv::Rect& f : found) {
    const cv::Rect in_image(static_cast<int>(f.x / scale) + roi.x, static_cast<int>(f.y / scale) + roi.y,
                            static_cast<int>(f.width / scale), static_cast<int>(f.height / scale));
    const double inside = (in_image & box).area();
    if (in_image.area() > 0 && inside / in_image.area() >= options_.min_overlap) return true;
  }
  return false;
}

}  // namespace mbslam
