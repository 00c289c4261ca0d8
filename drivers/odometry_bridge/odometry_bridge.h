#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_BRIDGE_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_BRIDGE_H_

// The bridge's main loop: reads odometry (ROS 2 over Fast DDS, CSV / TUM file, LCM
// pose_t), publishes odometry_t, and — with image_sync — the camera pose at every
// CAMERA_IMAGE time, reporting images that fall outside the odometry.

#include <deque>
#include <memory>
#include <string>

#include "common/lcm/lcm_bus.h"
#include "drivers/common/message_sink.h"
#include "drivers/odometry_bridge/image_odometry_sync.h"
#include "drivers/odometry_bridge/odometry_bridge_options.h"

namespace mbslam {

struct OdometryBridgeStats {
  int64_t received = 0;         // samples from the input
  int64_t published = 0;        // odometry_t messages
  int64_t rejected = 0;         // invalid samples (non-finite, bad quaternion)
  int64_t out_of_order = 0;     // samples not newer than the previous one, dropped
  int64_t camera_poses = 0;     // pose_t messages at image times
};

class OdometryBridge {
 public:
  // `sink` receives ODOMETRY (and camera poses). `bus` (may be null) carries the lcm
  // input and the images for image_sync; it may be the sink's bus.
  OdometryBridge(OdometryBridgeOptions options, MessageSink* sink, LcmBus* bus);
  ~OdometryBridge();

  // Runs until the end of a file input, max_messages, the idle timeout or shutdown.
  // On failure, exit_code() says which exit code the process should use.
  Status Run();
  int exit_code() const { return exit_code_; }

  const OdometryBridgeStats& stats() const { return stats_; }
  const ImageSyncStats* sync_stats() const { return sync_ ? &sync_->stats() : nullptr; }
  std::string Summary() const;

 private:
  Status Fail(int code, const std::string& message);
  Status HandleSample(OdometrySample sample);
  Status HandleImages();
  Status PublishSynced(const std::vector<ImageOdometry>& results);

  OdometryBridgeOptions options_;
  MessageSink* sink_;
  LcmBus* bus_;
  int exit_code_ = 0;
  std::unique_ptr<ImageOdometrySync> sync_;
  std::deque<OdometrySample> lcm_samples_;
  std::deque<ImageStamp> images_;
  std::optional<OdometrySample> previous_lcm_pose_;
  int64_t last_utime_ = INT64_MIN;
  int64_t reported_outside_ = 0;
  std::string input_description_;
  OdometryBridgeStats stats_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_BRIDGE_H_
