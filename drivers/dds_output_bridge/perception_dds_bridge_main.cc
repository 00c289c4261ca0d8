// perception_dds_bridge: the perception outputs (PERCEPTION_CAMERA_POSE,
// PERCEPTION_OBJECTS on LCM) as ROS 2 messages over Fast DDS.

#include <cstdio>
#include <iostream>

#include "common/config/options_yaml.h"
#include "common/lcm/lcm_bus.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "drivers/common/command_line.h"
#include "drivers/common/exit_codes.h"
#include "drivers/dds_output_bridge/perception_dds_bridge.h"
#include "drivers/dds_output_bridge/ros2_perception_publisher.h"

namespace mbslam {
namespace {

constexpr char kUsage[] = R"(usage: perception_dds_bridge [options]

Publishes the perception outputs to ROS 2 over Fast DDS, as ROS 2 puts them on the wire:
  PERCEPTION_CAMERA_POSE -> geometry_msgs/msg/PoseStamped     on /<prefix>/camera_pose
  PERCEPTION_OBJECTS     -> visualization_msgs/msg/MarkerArray on /<prefix>/objects
                            geometry_msgs/msg/PoseArray         on /<prefix>/object_poses
DDS never uses multicast: UDP on loopback (or listed interfaces) with unicast discovery,
or shared memory.

  --config FILE          option file (see config/perception_dds_bridge.yaml); defaults otherwise
  --lcm-url URL          LCM URL (default LCM's; file://LOG?speed=0 replays a log)
  --domain N             DDS domain id (ROS_DOMAIN_ID)
  --transport T          udp (loopback / listed interfaces, unicast discovery) | shm
  --prefix P             ROS 2 topic namespace (default mbslam)
  --frame-id F           header.frame_id of every message (default map)
  --wait-subscribers N   before reading LCM, wait until every output has N readers
  --set a.b=VALUE        set any option (repeatable)
  --print-config         print the effective options and exit
  --quiet                do not print the effective options at start
  --log-level L          debug | info | warning | error
  --help                 this text

Stops on SIGINT / SIGTERM, or at the end of a file:// log; prints the counts per
channel (received, published, bad, skipped) at exit.
Exit codes: 0 done, 1 unexpected error, 2 bad options, 4 LCM or DDS cannot be opened,
5 fewer subscribers than --wait-subscribers within wait_timeout_s.
)";

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "perception_dds_bridge: %s\n", message.c_str());
  return code;
}

std::string Quote(const std::string& value) {
  std::string q = "'";
  for (char c : value) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

int Main(int argc, char** argv) {
  CommandLine cl;
  const Status parsed = CommandLine::Parse(argc, argv, {"help", "print-config", "quiet"},
                                           {"config", "lcm-url", "domain", "transport", "prefix",
                                            "frame-id", "wait-subscribers", "set", "log-level"},
                                           &cl);
  if (!parsed.ok()) return Fail(kExitUsage, parsed.message());
  if (cl.Has("help")) {
    std::fputs(kUsage, stdout);
    return kExitOk;
  }
  if (!cl.positional().empty())
    return Fail(kExitUsage, "unexpected argument '" + cl.positional()[0] + "'");
  if (cl.Has("log-level")) {
    LogLevel level;
    if (!ParseLogLevel(cl.Get("log-level"), &level)) return Fail(kExitUsage, "bad --log-level");
    SetLogLevel(level);
  }
  PerceptionDdsBridgeOptions options;
  if (cl.Has("config")) {
    const Status st = LoadOptionsFromFile(cl.Get("config"), &options);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  struct Flag {
    const char* flag;
    const char* key;
    bool numeric;
  };
  const Flag kFlags[] = {
      {"lcm-url", "lcm_url", false},         {"domain", "dds.domain_id", true},
      {"transport", "dds.transport", false}, {"prefix", "topics.prefix", false},
      {"frame-id", "frame_id", false},       {"wait-subscribers", "wait_for_subscribers", true}};
  for (const Flag& f : kFlags) {
    if (!cl.Has(f.flag)) continue;
    const std::string value = f.numeric ? cl.Get(f.flag) : Quote(cl.Get(f.flag));
    const Status st = ApplyOptionAssignment(std::string(f.key) + "=" + value, &options);
    if (!st.ok()) return Fail(kExitUsage, "--" + std::string(f.flag) + ": " + st.message());
  }
  for (const std::string& assignment : cl.GetAll("set")) {
    const Status st = ApplyOptionAssignment(assignment, &options);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  if (cl.Has("print-config")) {
    std::cout << OptionsToYaml(options);
    return kExitOk;
  }
  if (!options.Check()) return Fail(kExitUsage, LastOptionError());
  if (!cl.Has("quiet")) {
    std::cout << "# perception_dds_bridge effective configuration\n"
              << OptionsToYaml(options) << std::flush;
  }
  InstallShutdownHandlers();

  Status st;
  std::unique_ptr<LcmBus> bus = LcmBus::Create(options.lcm_url, &st);
  if (!bus) return Fail(kExitOutputError, st.message());
  std::unique_ptr<Ros2PerceptionPublisher> publisher =
      Ros2PerceptionPublisher::Create(options.dds, options.topics, &st);
  if (!publisher) return Fail(kExitOutputError, st.message());
  MBSLAM_LOG(INFO) << "perception_dds_bridge: publishing " << publisher->description();

  // Subscribes now, so nothing published on a live bus while waiting is lost to us
  // (LCM queues up to queue_capacity messages per channel).
  PerceptionDdsBridge bridge(options, bus.get(), publisher.get());
  if (options.wait_for_subscribers > 0) {
    MBSLAM_LOG(INFO) << "perception_dds_bridge: waiting for " << options.wait_for_subscribers
                     << " subscriber(s) on every topic";
    const int64_t deadline = MonotonicUtime() + SecondsToUtime(options.wait_timeout_s);
    while (!ShutdownRequested() &&
           !publisher->WaitForReaders(options.wait_for_subscribers, 100 * kUsecPerMsec)) {
      if (MonotonicUtime() > deadline) {
        return Fail(kExitInputTimeout, "only " + std::to_string(publisher->min_matched_readers()) +
                                           " subscriber(s) after " +
                                           std::to_string(options.wait_timeout_s) + " s on " +
                                           publisher->description());
      }
    }
  }
  st = bridge.Run();
  // Reliable readers get what was written before the writers go away.
  if (options.linger_s > 0.0 && publisher->min_matched_readers() > 0 &&
      !publisher->WaitForAcknowledgments(SecondsToUtime(options.linger_s))) {
    MBSLAM_LOG(WARNING) << "perception_dds_bridge: not every sample was acknowledged within "
                        << options.linger_s << " s";
  }
  MBSLAM_LOG(INFO) << "perception_dds_bridge: "
                   << (ShutdownRequested() ? "stopped by signal" : "end of input") << "\n"
                   << bridge.Summary();
  if (!st.ok()) return Fail(kExitRuntimeError, st.message());
  return kExitOk;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) {
  try {
    return mbslam::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "perception_dds_bridge: unexpected error: %s\n", e.what());
    return mbslam::kExitRuntimeError;
  }
}
