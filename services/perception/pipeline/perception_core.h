#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_PERCEPTION_CORE_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_PERCEPTION_CORE_H_

// The coupled per-frame chain of the thesis (fig. 1.4): tracking -> segmentation ->
// SLAM -> object tracking -> fusion -> occupancy, with their feedback paths. Runs on
// the pipeline's processing thread; knows nothing of LCM.

#include <memory>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "common/config/options.h"
#include "services/perception/geometry/pose_buffer.h"
#include "services/perception/pipeline/counters.h"
#include "services/perception/pipeline/frame_processor.h"
#include "services/perception/pipeline/stage_timers.h"

namespace mbslam {

struct PreprocessOptions {
  int pyramid_levels = 4;  // image pyramid levels for tracking, level 0 = full resolution (count)
  int max_odometry_samples = 20000;  // odometry samples kept for interpolation (count)
  int64_t max_odometry_gap_us = 500000;  // largest odometry spacing to interpolate across (µs)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(pyramid_levels, 1);
    MBSLAM_CHECK_OPTION_LE(pyramid_levels, 8);
    MBSLAM_CHECK_OPTION_GT(max_odometry_samples, 1);
    MBSLAM_CHECK_OPTION_GT(max_odometry_gap_us, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("pyramid_levels", &pyramid_levels, "image pyramid levels, 0 = full resolution (count)");
    v("max_odometry_samples", &max_odometry_samples, "odometry samples kept (count)");
    v("max_odometry_gap_us", &max_odometry_gap_us, "largest odometry spacing to interpolate (us)");
  }
};

class PerceptionCore : public FrameProcessor {
 public:
  PerceptionCore(const PreprocessOptions& options, Counters* counters, StageTimers* timers);

  void OnOdometry(const OdometrySample& odometry) override;
  FrameResult ProcessFrame(const ImageFrame& frame) override;

  const PoseBuffer& odometry() const { return odometry_; }

 private:
  const PreprocessOptions options_;
  Counters* counters_;
  TimingStats* preprocess_timer_;
  PoseBuffer odometry_;
  std::vector<cv::Mat> pyramid_;
  int64_t frames_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_PERCEPTION_CORE_H_
