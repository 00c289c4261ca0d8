#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_DDS_ODOMETRY_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_DDS_ODOMETRY_H_

// ROS 2 nav_msgs/msg/Odometry over Fast DDS, exactly as ROS 2 puts it on the wire:
// topic rt/<name>, type nav_msgs::msg::dds_::Odometry_, classic CDR (the types are
// generated at build time from idl/ with fastddsgen). A reader for the bridge and a
// writer for tests and the test publisher.

#include <cstdint>
#include <memory>
#include <string>

#include "common/util/status.h"
#include "drivers/odometry_bridge/dds_options.h"
#include "drivers/odometry_bridge/odometry_sample.h"

namespace mbslam {

// ROS 2 stamp (sec, nanosec) to µs, rounded to the nearest µs.
int64_t Ros2StampToUtime(int32_t sec, uint32_t nanosec);
void UtimeToRos2Stamp(int64_t utime, int32_t* sec, uint32_t* nanosec);

class DdsOdometryReader {
 public:
  static std::unique_ptr<DdsOdometryReader> Create(const DdsOptions& options, Status* status);
  ~DdsOdometryReader();
  DdsOdometryReader(const DdsOdometryReader&) = delete;
  DdsOdometryReader& operator=(const DdsOdometryReader&) = delete;

  // The next message, converted; false after timeout_us without one.
  bool Pop(OdometrySample* sample, int64_t timeout_us);

  int64_t received() const;     // messages taken from DDS
  int64_t rejected() const;     // of those, invalid (non-finite, bad quaternion)
  int64_t renormalised() const; // quaternions off unit norm by 1e-6..1e-2, normalised
  int64_t dropped() const;      // lost to a full queue
  int matched_writers() const;  // publishers currently matched
  std::string last_rejection() const;
  std::string description() const;

  struct Impl;

 private:
  explicit DdsOdometryReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

class DdsOdometryWriter {
 public:
  // A reliable, keep-all writer (so a test sends every message to a reliable reader).
  static std::unique_ptr<DdsOdometryWriter> Create(const DdsOptions& options, Status* status);
  ~DdsOdometryWriter();
  DdsOdometryWriter(const DdsOdometryWriter&) = delete;
  DdsOdometryWriter& operator=(const DdsOdometryWriter&) = delete;

  // Waits until at least `count` readers matched; false on timeout.
  bool WaitForReaders(int count, int64_t timeout_us);
  Status Write(const OdometrySample& sample);
  // Waits until reliable readers acknowledged everything written.
  bool WaitForAcknowledgments(int64_t timeout_us);

  struct Impl;

 private:
  explicit DdsOdometryWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_DDS_ODOMETRY_H_
