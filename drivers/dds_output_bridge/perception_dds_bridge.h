#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_DDS_BRIDGE_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_DDS_BRIDGE_H_

// The LCM side of perception_dds_bridge: subscribes to PERCEPTION_CAMERA_POSE and
// PERCEPTION_OBJECTS, decodes every message with the bounds-checked DecodeLcmMessage,
// converts it (ros2_perception_conversion.h) and hands it to the DDS writers. Bad
// messages (truncated, corrupted, wrong type, non-finite poses, times outside ROS 2's
// range) are counted per channel, logged (the first few, then one in a hundred) and
// dropped; nothing here throws or stops on bad input.

#include <cstdint>
#include <string>

#include "common/lcm/lcm_bus.h"
#include "common/util/status.h"
#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"
#include "drivers/dds_output_bridge/ros2_perception_publisher.h"

namespace mbslam {

struct BridgeChannelCounts {
  int64_t received = 0;         // LCM messages seen (count)
  int64_t bad = 0;              // undecodable or invalid, dropped (count)
  int64_t skipped = 0;          // valid but not for ROS (camera poses while not tracking) (count)
  int64_t published = 0;        // LCM messages published on DDS (count)
  int64_t write_failures = 0;   // DDS samples Fast DDS refused (count)
  int64_t invalid_objects = 0;  // objects left out of otherwise good messages (count)
  int64_t renormalised = 0;     // quaternions off unit norm by 1e-6..1e-2, normalised (count)
  std::string last_error;       // reason of the last bad message or invalid object
};

class PerceptionDdsBridge {
 public:
  // Subscribes on `bus` to the channels the enabled outputs need. `bus` and `publisher`
  // must outlive the bridge.
  PerceptionDdsBridge(const PerceptionDdsBridgeOptions& options, LcmBus* bus,
                      Ros2PerceptionPublisher* publisher);

  // Dispatches LCM messages until SIGINT / SIGTERM (ShutdownRequested()) or, with a
  // file:// URL and exit_at_end_of_log, the end of the log. Fails only when the bus does.
  Status Run();

  const BridgeChannelCounts& camera_pose_counts() const { return camera_pose_; }
  const BridgeChannelCounts& objects_counts() const { return objects_; }
  int64_t bad_total() const { return camera_pose_.bad + objects_.bad; }
  // One line per channel with every count.
  std::string Summary() const;

 private:
  void OnCameraPose(const uint8_t* data, size_t size);
  void OnObjects(const uint8_t* data, size_t size);
  void Bad(BridgeChannelCounts* counts, const std::string& channel, const std::string& why);
  void WriteFailed(BridgeChannelCounts* counts, const std::string& channel, const Status& status);

  PerceptionDdsBridgeOptions options_;
  LcmBus* bus_;
  Ros2PerceptionPublisher* publisher_;
  size_t max_message_bytes_;
  BridgeChannelCounts camera_pose_;
  BridgeChannelCounts objects_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_DDS_BRIDGE_H_
