#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_FRAME_PROCESSOR_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_FRAME_PROCESSOR_H_

#include "services/perception/pipeline/outputs.h"
#include "services/perception/pipeline/payloads.h"

namespace mbslam {

// The algorithm chain run for every image, on the pipeline's processing thread, in
// event order. Implementations know nothing of LCM or threads.
class FrameProcessor {
 public:
  virtual ~FrameProcessor() = default;
  virtual void OnOdometry(const OdometrySample& odometry) = 0;
  virtual FrameResult ProcessFrame(const ImageFrame& frame) = 0;
  // Called once after the last event (end of a replay or shutdown).
  virtual void Finish() {}
  // After Finish(): the camera poses as the map finally has them ((utime,
  // world_from_cam), oldest first; see OutputSink::OnAdjustedCameraTrajectory).
  virtual std::vector<std::pair<int64_t, Rigid3d>> AdjustedCameraTrajectory() const { return {}; }
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_FRAME_PROCESSOR_H_
