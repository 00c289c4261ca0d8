#ifndef MBSLAM_SERVICES_PERCEPTION_LCM_ADAPTERS_INPUT_ADAPTER_H_
#define MBSLAM_SERVICES_PERCEPTION_LCM_ADAPTERS_INPUT_ADAPTER_H_

// Turns CAMERA_IMAGE, CAMERA_CALIBRATION, ODOMETRY and SNAPSHOT_REQUEST messages into
// pipeline payloads. Every message is bounds-checked before decoding; anything
// malformed, inconsistent or out of order is counted and dropped, never thrown.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "common/config/options.h"
#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "services/perception/geometry/camera.h"
#include "services/perception/pipeline/counters.h"
#include "services/perception/pipeline/pipeline.h"

namespace mbslam {

struct InputOptions {
  std::string calibration_file;      // intrinsics YAML used until / unless CAMERA_CALIBRATION arrives; "" = none
  bool use_calibration_messages = true;  // take CAMERA_CALIBRATION messages (newest wins)
  double fallback_focal_factor = 1.0;    // uncalibrated images get fx = fy = factor * width; 0 = reject them
  int64_t max_message_bytes = 67108864;  // larger messages are dropped before decoding (bytes)
  int time_reset_after_frames = 15;      // this many consecutive frames with time going back start a new timeline (count)
  int subscription_queue = 100;          // LCM's per-subscription queue (messages)
  int64_t odometry_timeout_us = 500000;  // once odometry flows, an image this much newer than the last sample counts as without odometry (µs)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(fallback_focal_factor, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_message_bytes, 1024);
    MBSLAM_CHECK_OPTION_GT(time_reset_after_frames, 0);
    MBSLAM_CHECK_OPTION_GT(subscription_queue, 0);
    MBSLAM_CHECK_OPTION_GT(odometry_timeout_us, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("calibration_file", &calibration_file, "intrinsics YAML used until CAMERA_CALIBRATION arrives (\"\" = none)");
    v("use_calibration_messages", &use_calibration_messages, "take CAMERA_CALIBRATION messages");
    v("fallback_focal_factor", &fallback_focal_factor, "uncalibrated images: fx = fy = factor * width; 0 = reject");
    v("max_message_bytes", &max_message_bytes, "larger messages are dropped undecoded (bytes)");
    v("time_reset_after_frames", &time_reset_after_frames, "consecutive backwards frames that start a new timeline (count)");
    v("subscription_queue", &subscription_queue, "LCM per-subscription queue (messages)");
    v("odometry_timeout_us", &odometry_timeout_us, "image newer than the last odometry by this = without odometry (us)");
  }
};

class InputAdapter {
 public:
  // Loads options.calibration_file when set.
  static std::unique_ptr<InputAdapter> Create(const InputOptions& options,
                                              const PipelineOptions& pipeline_options,
                                              PerceptionPipeline* pipeline, Counters* counters,
                                              Status* status);

  void Subscribe(LcmBus* bus, const ChannelOptions& channels);

  // Message handlers (also called directly by tests and fuzz targets).
  void HandleImage(const uint8_t* data, size_t size, int64_t wall_utime);
  void HandleCalibration(const uint8_t* data, size_t size);
  void HandleOdometry(const uint8_t* data, size_t size);
  void HandleSnapshotRequest(const uint8_t* data, size_t size);

  // Called for every valid snapshot request (path prefix, bit set of what).
  void set_snapshot_callback(std::function<void(const std::string&, int)> callback) {
    snapshot_callback_ = std::move(callback);
  }
  // Latest image time accepted (µs), 0 before the first.
  int64_t last_image_utime() const { return last_image_utime_; }

 private:
  InputAdapter(const InputOptions& options, const PipelineOptions& pipeline_options,
               PerceptionPipeline* pipeline, Counters* counters);
  void Reject(const char* counter_name, const std::string& why);

  const InputOptions options_;
  const int max_image_dimension_;
  const int64_t max_frame_gap_us_;
  PerceptionPipeline* pipeline_;
  Counters* counters_;
  std::shared_ptr<const CameraIntrinsics> intrinsics_;
  std::shared_ptr<const CameraIntrinsics> fallback_;  // cached approximate intrinsics
  int64_t last_image_utime_ = 0;
  int64_t last_seq_ = -1;
  int backwards_streak_ = 0;
  int last_width_ = 0;          // size of the last accepted image (px)
  int last_height_ = 0;
  int size_change_streak_ = 0;  // consecutive images of another size (count)
  int64_t last_odometry_utime_ = 0;
  // Message time from which odometry staleness is measured: the last valid sample, or
  // the start of a new timeline; 0 until odometry was first seen.
  int64_t odometry_clock_utime_ = 0;
  bool odometry_stale_ = false;  // images are arriving without odometry
  std::function<void(const std::string&, int)> snapshot_callback_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_LCM_ADAPTERS_INPUT_ADAPTER_H_
