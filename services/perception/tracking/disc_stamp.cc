#include "services/perception/tracking/disc_stamp.h"

#include <algorithm>
#include <cstring>

#include <opencv2/imgproc.hpp>

namespace mbslam {

DiscStamp::DiscStamp(int radius) : radius_(std::max(0, radius)) {
  const int side = 2 * radius_ + 1;
  cv::Mat disc(side, side, CV_8UC1, cv::Scalar(0));
  cv::circle(disc, cv::Point(radius_, radius_), radius_, cv::Scalar(255), cv::FILLED);
  half_width_.assign(static_cast<size_t>(side), -1);
  for (int r = 0; r < side; ++r) {
    const uint8_t* row = disc.ptr<uint8_t>(r);
    int lo = side, hi = -1;
    for (int c = 0; c < side; ++c) {
      if (!row[c]) continue;
      lo = std::min(lo, c);
      hi = std::max(hi, c);
    }
    if (hi < 0) continue;
    // A filled disc's rows are single runs, symmetric about the centre.
    half_width_[static_cast<size_t>(r)] = std::max(radius_ - lo, hi - radius_);
  }
}

void DiscStamp::Stamp(cv::Mat* mask, cv::Point centre, uint8_t value) const {
  const int y0 = std::max(0, centre.y - radius_), y1 = std::min(mask->rows - 1, centre.y + radius_);
  for (int y = y0; y <= y1; ++y) {
    const int h = half_width_[static_cast<size_t>(y - centre.y + radius_)];
    if (h < 0) continue;
    const int x0 = std::max(0, centre.x - h), x1 = std::min(mask->cols - 1, centre.x + h);
    if (x0 > x1) continue;
    std::memset(mask->ptr<uint8_t>(y) + x0, value, static_cast<size_t>(x1 - x0 + 1));
  }
}

}  // namespace mbslam
