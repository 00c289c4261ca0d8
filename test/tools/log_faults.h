#ifndef MBSLAM_TEST_TOOLS_LOG_FAULTS_H_
#define MBSLAM_TEST_TOOLS_LOG_FAULTS_H_

// Rewrites a recorded input log with one fault at a time, for the fault-injection
// integration tests and the lcm_fault_inject tool. Frames are the CAMERA_IMAGE events,
// numbered from 0 in log order; "the event of frame k" is its position in the log.
// Every input type starts with `int64_t utime` (the contract's convention), so time
// edits patch that field in place; the other edits decode, change and re-encode.

#include <cstdint>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_log.h"
#include "common/util/status.h"

namespace mbslam {
namespace fault {

class LogEditor {
 public:
  explicit LogEditor(std::vector<LcmLogEvent> events, ChannelOptions channels = ChannelOptions());
  static Status Load(const std::string& path, LogEditor* editor);
  Status Write(const std::string& path) const;

  const std::vector<LcmLogEvent>& events() const { return events_; }
  int num_frames() const;
  // Message time of frame k (µs); 0 when k is out of range.
  int64_t FrameUtime(int frame) const;

  // Preparation (not faults): keeps the events before frame `num_frames`; removes a
  // channel; adds ODOMETRY after every GROUND_TRUTH camera pose, at the same time, for
  // a robot whose camera sits at base_from_cam (rotation [w, x, y, z], translation m):
  // odom_from_base = world_from_cam * base_from_cam^-1.
  void Truncate(int num_frames);
  int DropChannel(const std::string& channel);
  Status AddOdometryFromTruth(const double base_from_cam_wxyz[4], const double base_from_cam_t[3]);

  // Drops each frame in [first_frame, end_frame) with probability `fraction` (seeded).
  // Returns the number dropped.
  int DropFrames(double fraction, uint32_t seed, int first_frame, int end_frame);
  // Adds delta_us to the message time (and the event time) of every input message from
  // the event of frame `from_frame` on: a step of the shared sensor clock.
  Status ShiftTime(int from_frame, int64_t delta_us);
  // Removes the ODOMETRY messages with utime in [from_utime, to_utime). Returns how many.
  int DropOdometry(int64_t from_utime, int64_t to_utime);
  // Sets the pose and twist of the ODOMETRY messages with utime in [from_utime, to_utime)
  // to `value` (NaN or infinity): position[k], orientation[(k+1)%4], velocities,
  // rotating which field is hit. Returns how many were changed.
  int CorruptOdometry(int64_t from_utime, int64_t to_utime, double value);
  // Inserts, just before the event of frame `at_frame`, a copy of the last calibration
  // before it with fx, cy and one distortion slot replaced by `value`. Needs a
  // CAMERA_CALIBRATION before that frame.
  Status InjectBadCalibration(int at_frame, double value);
  // Replaces frame k by the same picture resized to width x height (raw encodings).
  Status ResizeFrame(int frame, int width, int height);
  // Delivery burst: frames [first_frame, first_frame + count) and the messages between
  // them are held back and then delivered at `factor` times the frame rate, the last
  // one at its normal time (a stall, then a backlog flushed). Only the log's event
  // times change (what a replay at speed 1 paces by); message times are untouched.
  Status Burst(int first_frame, int count, double factor);

 private:
  std::vector<size_t> FrameEvents() const;
  bool IsInput(const std::string& channel) const;

  std::vector<LcmLogEvent> events_;
  ChannelOptions channels_;
};

// Reads / writes the big-endian int64 utime that starts every input message.
bool ReadMessageUtime(const std::vector<uint8_t>& data, int64_t* utime);
void WriteMessageUtime(std::vector<uint8_t>* data, int64_t utime);

}  // namespace fault
}  // namespace mbslam

#endif  // MBSLAM_TEST_TOOLS_LOG_FAULTS_H_
