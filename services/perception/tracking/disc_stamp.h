#ifndef MBSLAM_SERVICES_PERCEPTION_TRACKING_DISC_STAMP_H_
#define MBSLAM_SERVICES_PERCEPTION_TRACKING_DISC_STAMP_H_

// A filled disc of a fixed radius written into an 8-bit mask: the pixels
// cv::circle(mask, centre, radius, value, cv::FILLED) sets, clipped to the mask, as one
// run per row taken from a disc drawn by cv::circle once (its rasterisation depends on
// the centre only by translation). Cheaper than cv::circle when stamped many times.

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace mbslam {

class DiscStamp {
 public:
  explicit DiscStamp(int radius);
  int radius() const { return radius_; }
  // Sets the disc's pixels around `centre` (any integer point, inside the mask or not).
  void Stamp(cv::Mat* mask, cv::Point centre, uint8_t value) const;

 private:
  int radius_ = 0;
  std::vector<int> half_width_;  // per row dy = -radius .. radius: the run is centre.x +- it; -1 = empty
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_TRACKING_DISC_STAMP_H_
