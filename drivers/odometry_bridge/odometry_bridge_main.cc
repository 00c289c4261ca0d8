// odometry_bridge: robot odometry (ROS 2 nav_msgs/Odometry over Fast DDS, CSV / TUM
// files, an LCM pose_t channel) to ODOMETRY (odometry_t) on LCM or into an LCM log.

#include <cstdio>
#include <iostream>

#include "common/config/options_yaml.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "drivers/common/command_line.h"
#include "drivers/common/exit_codes.h"
#include "drivers/common/message_sink.h"
#include "drivers/odometry_bridge/odometry_bridge.h"

namespace mbslam {
namespace {

constexpr char kUsage[] = R"(usage: odometry_bridge [options]

Publishes robot odometry as ODOMETRY (odometry_t) on LCM, or writes it to an LCM log.

  --config FILE        option file (see config/odometry_bridge.yaml); defaults otherwise
  --input I            dds (ROS 2 nav_msgs/Odometry over Fast DDS) | csv | tum | lcm (pose_t)
  --file FILE          csv / tum input
  --topic T            ROS 2 topic (DDS topic rt/T), default odom
  --domain N           DDS domain id (ROS_DOMAIN_ID)
  --transport T        shm | udp (loopback / listed interfaces only)
  --reliable           reliable DDS reader (default best effort, which matches any writer)
  --log FILE           write an LCM log (event time = message time) instead of publishing
  --lcm-url URL        LCM URL (outputs, the lcm input and the images for --image-sync)
  --speed X            file inputs: 1 = recorded rate, N x, 0 = as fast as possible
  --max-messages N     stop after N messages;  --idle-timeout S  stop after S s without input
  --image-sync         also publish odom_from_cam at every CAMERA_IMAGE time
  --extrinsic FILE     base_from_cam YAML (translation + quaternion [w,x,y,z])
  --set a.b=VALUE      set any option (repeatable)
  --print-config       print the effective options and exit
  --quiet              do not print the effective options at start
  --log-level L        debug | info | warning | error

Exit codes: 0 done, 1 unexpected error, 2 bad options / input file, 3 input not found,
4 output error, 5 no input within --idle-timeout.
)";

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "odometry_bridge: %s\n", message.c_str());
  return code;
}

std::string Quote(const std::string& value) {
  std::string q = "'";
  for (char c : value) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

int Main(int argc, char** argv) {
  CommandLine cl;
  const Status parsed = CommandLine::Parse(
      argc, argv, {"help", "reliable", "image-sync", "print-config", "quiet"},
      {"config", "input", "file", "topic", "domain", "transport", "log", "lcm-url", "speed",
       "max-messages", "idle-timeout", "extrinsic", "set", "log-level"},
      &cl);
  if (!parsed.ok()) return Fail(kExitUsage, parsed.message());
  if (cl.Has("help")) {
    std::fputs(kUsage, stdout);
    return kExitOk;
  }
  if (!cl.positional().empty()) return Fail(kExitUsage, "unexpected argument '" + cl.positional()[0] + "'");
  if (cl.Has("log-level")) {
    LogLevel level;
    if (!ParseLogLevel(cl.Get("log-level"), &level)) return Fail(kExitUsage, "bad --log-level");
    SetLogLevel(level);
  }
  OdometryBridgeOptions options;
  if (cl.Has("config")) {
    const Status st = LoadOptionsFromFile(cl.Get("config"), &options);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  const std::pair<const char*, std::string> kFlags[] = {
      {"input", "input"}, {"file", "file"}, {"topic", "dds.topic"}, {"domain", "dds.domain_id"},
      {"transport", "dds.transport"}, {"lcm-url", "lcm_url"}, {"speed", "speed"},
      {"max-messages", "max_messages"}, {"idle-timeout", "idle_timeout_s"},
      {"extrinsic", "base_from_cam.file"}};
  for (const auto& [flag, key] : kFlags) {
    if (!cl.Has(flag)) continue;
    const bool numeric = key == "dds.domain_id" || key == "speed" || key == "max_messages" ||
                         key == "idle_timeout_s";
    const std::string value = numeric ? cl.Get(flag) : Quote(cl.Get(flag));
    const Status st = ApplyOptionAssignment(key + "=" + value, &options);
    if (!st.ok()) return Fail(kExitUsage, "--" + std::string(flag) + ": " + st.message());
  }
  if (cl.Has("reliable")) options.dds.reliable = true;
  if (cl.Has("image-sync")) options.image_sync.enabled = true;
  for (const std::string& assignment : cl.GetAll("set")) {
    const Status st = ApplyOptionAssignment(assignment, &options);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  if (cl.Has("print-config")) {
    std::cout << OptionsToYaml(options);
    return kExitOk;
  }
  if (!cl.Has("quiet")) {
    std::cout << "# odometry_bridge effective configuration\n" << OptionsToYaml(options) << std::flush;
  }
  InstallShutdownHandlers();

  // One bus for everything LCM (memq:// is one bus per instance); the output is the
  // bus unless --log is given.
  const std::string log_path = cl.Get("log");
  const bool need_bus = log_path.empty() || options.input == "lcm" || options.image_sync.enabled;
  std::unique_ptr<LcmBus> bus;
  Status st;
  if (need_bus) {
    bus = LcmBus::Create(options.lcm_url, &st);
    if (!bus) return Fail(kExitOutputError, st.message());
  }
  std::unique_ptr<MessageSink> sink;
  if (!log_path.empty()) {
    sink = LcmLogSink::Create(log_path, &st);
    if (!sink) return Fail(kExitOutputError, st.message());
  } else {
    sink = std::make_unique<LcmBusSink>(bus.get());
  }
  OdometryBridge bridge(options, sink.get(), bus.get());
  st = bridge.Run();
  MBSLAM_LOG(INFO) << bridge.Summary();
  if (!st.ok()) return Fail(bridge.exit_code(), st.message());
  return kExitOk;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) {
  try {
    return mbslam::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "odometry_bridge: unexpected error: %s\n", e.what());
    return mbslam::kExitRuntimeError;
  }
}
