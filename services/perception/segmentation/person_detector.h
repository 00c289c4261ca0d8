#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_PERSON_DETECTOR_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_PERSON_DETECTOR_H_

// Person detection restricted to moving regions (thesis sec. 3.9.4): OpenCV's HOG
// people detector runs only inside the (padded) bounding box of a moving object, so
// its cost follows the moving area, not the image. A large region is scaled down first
// (a person filling it stays well above the 64x128 detector window), so the cost of one
// check is bounded whatever the object's size.

#include <opencv2/core/mat.hpp>
#include <opencv2/objdetect.hpp>

#include "common/config/options.h"

namespace mbslam {

struct PersonDetectorOptions {
  bool enabled = true;             // run the detector on moving objects
  int every_n_frames = 5;          // per object, at most once per this many images (frames)
  double padding = 0.25;           // box grown by this fraction on each side (and to one detector window at least)
  double hit_threshold = 0.3;      // SVM margin of a detection
  double min_overlap = 0.3;        // detection area inside the object's box / detection area
  int min_box_height_px = 48;      // smaller moving regions are not tried (px)
  int max_box_height_px = 192;     // larger regions are scaled down to this height first (px; bounds the cost)
  double scale_step = 1.05;        // HOG pyramid step between detection scales
  int max_checks_per_frame = 1;    // objects checked per image at most, least recently checked first (count)
  int job_nice = 10;               // niceness of the thread the service runs the checks in (0-19)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(every_n_frames, 1);
    MBSLAM_CHECK_OPTION_GE(padding, 0.0);
    MBSLAM_CHECK_OPTION(min_overlap >= 0.0 && min_overlap <= 1.0);
    MBSLAM_CHECK_OPTION_GT(min_box_height_px, 0);
    MBSLAM_CHECK_OPTION_GE(max_box_height_px, 128);
    MBSLAM_CHECK_OPTION(scale_step > 1.0 && scale_step <= 2.0);
    MBSLAM_CHECK_OPTION_GE(max_checks_per_frame, 1);
    MBSLAM_CHECK_OPTION(job_nice >= 0 && job_nice <= 19);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("enabled", &enabled, "run HOG people detection on moving objects");
    v("every_n_frames", &every_n_frames, "per object at most once per (frames)");
    v("padding", &padding, "object box grown by this fraction per side");
    v("hit_threshold", &hit_threshold, "HOG SVM margin of a detection");
    v("min_overlap", &min_overlap, "fraction of a detection inside the object's box");
    v("min_box_height_px", &min_box_height_px, "smaller regions are not tried (px)");
    v("max_box_height_px", &max_box_height_px, "larger regions are scaled down to this height first (px)");
    v("scale_step", &scale_step, "HOG pyramid step between detection scales");
    v("max_checks_per_frame", &max_checks_per_frame, "objects checked per image at most, least recently checked first");
    v("job_nice", &job_nice,
      "niceness of the thread the checks run in, one image behind (0-19; tracking's threads go first)");
  }
};

class PersonDetector {
 public:
  explicit PersonDetector(const PersonDetectorOptions& options);
  // True if a person is found overlapping `box` in the gray image.
  bool Detect(const cv::Mat& gray, const cv::Rect& box) const;

 private:
  PersonDetectorOptions options_;
  mutable cv::HOGDescriptor hog_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_PERSON_DETECTOR_H_
