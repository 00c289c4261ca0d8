#ifndef MBSLAM_DRIVERS_CAMERA_CAMERA_DRIVER_H_
#define MBSLAM_DRIVERS_CAMERA_CAMERA_DRIVER_H_

// The camera driver's main loop: opens a source (retrying when asked), publishes
// every frame as image_t with the calibration (first frame, then periodically) and
// the dataset's ground truth, paces file sources, loops, counts bad frames and
// reconnects lost cameras.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "drivers/camera/camera_driver_options.h"
#include "drivers/camera/frame_source.h"
#include "drivers/common/message_sink.h"
#include "services/perception/geometry/camera.h"

namespace mbslam {

// The source named by options.source.
std::unique_ptr<FrameSource> CreateFrameSource(const CameraDriverOptions& options);

struct CameraDriverStats {
  int64_t frames_read = 0;          // frames the source delivered in range (good and bad)
  int64_t frames_published = 0;     // image_t messages
  int64_t bad_frames = 0;           // unreadable / undecodable frames skipped (count)
  int64_t size_mismatches = 0;      // frames whose size differs from the calibration, skipped (count)
  int64_t calibrations_published = 0;
  int64_t truth_published = 0;      // ground_truth_t messages
  int64_t truth_missing = 0;        // of those, without a camera pose (count)
  int64_t reconnects = 0;           // successful reconnections of a live camera
  int loops_done = 0;               // complete passes over a file source
  std::vector<std::string> bad_frame_examples;  // the first few reasons
};

class CameraDriver {
 public:
  // `source` and `sink` must outlive the driver. Pacing applies to file sources
  // published on a bus (not to logs) with playback.speed > 0.
  CameraDriver(CameraDriverOptions options, FrameSource* source, MessageSink* sink);

  // Opens the source and publishes until the end of the input, the loop count, a
  // shutdown request or a fatal error. OK at the end of input and on shutdown.
  SourceStatus Run();

  const CameraDriverStats& stats() const { return stats_; }
  const std::optional<CameraIntrinsics>& intrinsics() const { return intrinsics_; }
  std::string Summary() const;

 private:
  SourceStatus OpenSource(bool reconnecting);
  SourceStatus ResolveCalibration(const Frame& first);
  SourceStatus PublishFrame(Frame* frame);
  void CountBadFrame(const std::string& reason);

  CameraDriverOptions options_;
  FrameSource* source_;
  MessageSink* sink_;
  std::optional<CameraIntrinsics> intrinsics_;
  std::string camera_name_;
  int64_t next_seq_ = 0;
  int64_t last_calibration_utime_ = 0;
  bool calibration_sent_ = false;
  CameraDriverStats stats_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_CAMERA_DRIVER_H_
