#include "services/perception/pipeline/perception_core.h"

#include <opencv2/video/tracking.hpp>

#include "common/util/logging.h"

namespace mbslam {

PerceptionCore::PerceptionCore(const PreprocessOptions& options, Counters* counters,
                               StageTimers* timers)
    : options_(options),
      counters_(counters),
      preprocess_timer_(timers->Get("preprocess")),
      odometry_(options.max_odometry_gap_us, static_cast<size_t>(options.max_odometry_samples)) {}

void PerceptionCore::OnOdometry(const OdometrySample& odometry) {
  const Status status = odometry_.Insert(odometry.utime, odometry.odom_from_base);
  if (!status.ok()) {
    counters_->Increment(odometry_.empty() || odometry.utime > odometry_.last_utime()
                             ? counter::kOdometryInvalid
                             : counter::kOdometryTimeBackwards);
  }
}

FrameResult PerceptionCore::ProcessFrame(const ImageFrame& frame) {
  if (frame.timeline_reset) {
    odometry_.Clear();
    MBSLAM_LOG(WARNING) << "image time went back for good at " << frame.utime << ": starting over";
  }
  FrameResult result;
  result.utime = frame.utime;
  result.frame_seq = frame.seq;
  result.width = frame.gray.cols;
  result.height = frame.gray.rows;
  {
    ScopedStageTimer timer(preprocess_timer_);
    cv::buildOpticalFlowPyramid(frame.gray, pyramid_, cv::Size(21, 21), options_.pyramid_levels - 1);
  }
  ++frames_;
  result.camera_pose.utime = frame.utime;
  result.camera_pose.frame_seq = frame.seq;
  result.camera_pose.tracking_state = TrackingState::kNotInitialized;
  return result;
}

}  // namespace mbslam
