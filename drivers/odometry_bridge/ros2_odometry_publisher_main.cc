// ros2_odometry_publisher: publishes nav_msgs/msg/Odometry over Fast DDS exactly as a
// ROS 2 robot does (rt/<topic>, nav_msgs::msg::dds_::Odometry_), from the same IDL as
// the bridge. For tests and demos; shared memory or loopback UDP only.
//
//   ros2_odometry_publisher [--topic odom] [--domain N] [--transport shm|udp]
//       [--count N] [--rate HZ] [--pattern fields|screw] [--wait-readers S]

#include <chrono>
#include <cstdio>
#include <thread>

#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "drivers/common/command_line.h"
#include "drivers/common/exit_codes.h"
#include "drivers/odometry_bridge/dds_odometry.h"
#include "drivers/odometry_bridge/test_trajectory.h"

int main(int argc, char** argv) {
  using namespace mbslam;
  CommandLine cl;
  Status st = CommandLine::Parse(argc, argv, {"help"},
                                 {"topic", "domain", "transport", "count", "rate", "pattern", "wait-readers"}, &cl);
  if (!st.ok() || cl.Has("help")) {
    std::fprintf(stderr,
                 "%s%susage: ros2_odometry_publisher [--topic odom] [--domain N] [--transport shm|udp]\n"
                 "  [--count N] [--rate HZ] [--pattern fields|screw] [--wait-readers S]\n",
                 st.ok() ? "" : st.message().c_str(), st.ok() ? "" : "\n");
    return st.ok() ? kExitOk : kExitUsage;
  }
  DdsOptions dds;
  dds.topic = cl.Get("topic", "odom");
  dds.transport = cl.Get("transport", "shm");
  int64_t domain = 0, count = 100;
  double rate = 50.0, wait_s = 10.0;
  for (const Status& s : {ParseInt64(cl.Get("domain", "0"), "--domain", &domain),
                          ParseInt64(cl.Get("count", "100"), "--count", &count),
                          ParseDouble(cl.Get("rate", "50"), "--rate", &rate),
                          ParseDouble(cl.Get("wait-readers", "10"), "--wait-readers", &wait_s)}) {
    if (!s.ok()) {
      std::fprintf(stderr, "ros2_odometry_publisher: %s\n", s.message().c_str());
      return kExitUsage;
    }
  }
  const std::string pattern = cl.Get("pattern", "fields");
  if ((pattern != "fields" && pattern != "screw") || rate <= 0 || count < 0) {
    std::fprintf(stderr, "ros2_odometry_publisher: bad --pattern, --rate or --count\n");
    return kExitUsage;
  }
  dds.domain_id = static_cast<int>(domain);
  InstallShutdownHandlers();
  std::unique_ptr<DdsOdometryWriter> writer = DdsOdometryWriter::Create(dds, &st);
  if (!writer) {
    std::fprintf(stderr, "ros2_odometry_publisher: %s\n", st.message().c_str());
    return kExitRuntimeError;
  }
  if (!writer->WaitForReaders(1, SecondsToUtime(wait_s))) {
    std::fprintf(stderr, "ros2_odometry_publisher: no reader on %s within %g s\n",
                 Ros2TopicToDds(dds.topic).c_str(), wait_s);
    return kExitInputTimeout;
  }
  const ScrewTrajectory screw;
  const int64_t period_us = static_cast<int64_t>(1e6 / rate);
  int64_t next = MonotonicUtime();
  for (int64_t i = 0; i < count && !ShutdownRequested(); ++i) {
    const OdometrySample sample =
        pattern == "fields" ? FieldTestOdometry(i) : screw.Sample(screw.t0_utime + 20000 * i, i);
    st = writer->Write(sample);
    if (!st.ok()) {
      std::fprintf(stderr, "ros2_odometry_publisher: %s\n", st.message().c_str());
      return kExitRuntimeError;
    }
    next += period_us;
    const int64_t wait = next - MonotonicUtime();
    if (wait > 0) std::this_thread::sleep_for(std::chrono::microseconds(wait));
  }
  if (!writer->WaitForAcknowledgments(5 * kUsecPerSec)) {
    std::fprintf(stderr, "ros2_odometry_publisher: not every message was acknowledged\n");
  }
  std::printf("ros2_odometry_publisher: published %lld messages on %s\n", static_cast<long long>(count),
              Ros2TopicToDds(dds.topic).c_str());
  return kExitOk;
}
