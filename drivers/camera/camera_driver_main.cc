// camera_driver: publishes a camera or a dataset on LCM (CAMERA_IMAGE,
// CAMERA_CALIBRATION, GROUND_TRUTH), or writes it to an LCM log with --log.

#include <cstdio>
#include <iostream>
#include <string>

#include "common/config/options_yaml.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "drivers/camera/camera_driver.h"
#include "drivers/camera/dc1394_source.h"
#include "drivers/common/command_line.h"
#include "drivers/common/exit_codes.h"
#include "drivers/common/message_sink.h"

namespace mbslam {
namespace {

constexpr char kUsage[] = R"(usage: camera_driver [options]

Publishes images from a camera or a dataset on LCM, or writes them to an LCM log.

  --config FILE          option file (see config/camera_driver.yaml); defaults otherwise
  --source S             dc1394 | v4l2 | video | folder | tum | kitti | tartanair | sequence
  --input PATH           video file or folder of a file source
  --log FILE             write an LCM log (event time = message time) instead of publishing
  --lcm-url URL          LCM URL to publish on (default: LCM's default)
  --calibration FILE     intrinsics YAML (config/camera/*.yaml)
  --camera-name NAME     image_t.camera_name
  --speed X              file sources: 1 = recorded rate, N = N x, 0 = as fast as possible
  --rate HZ              frame rate of folders / TartanAir without timestamps
  --timestamps FILE      timestamps of an image folder (unit: folder.timestamps_unit)
  --start-frame N        first frame index;  --end-frame N  index after the last
  --loops N              play N times (0 = forever)
  --encoding E           raw | jpeg | png | source
  --color C              keep | gray | bgr
  --ground-truth FILE    truth file (--gt-format tum | kitti | tartanair)
  --device DEV           V4L2 device (/dev/video0 or 0)
  --guid G               IEEE 1394 camera GUID (hex)
  --mode M               IEEE 1394 video mode (640x480_MONO8, FORMAT7_0, ...)
  --fps X                camera frame rate (dc1394 and v4l2)
  --reconnect            keep retrying a missing or lost camera
  --set a.b=VALUE        set any option (repeatable), e.g. --set image.jpeg_quality=80
  --list-cameras         list IEEE 1394 cameras and V4L2 devices, then exit
  --print-config         print the effective options and exit
  --no-progress          no progress bar
  --quiet                do not print the effective options at start
  --log-level L          debug | info | warning | error

Exit codes: 0 done, 1 unexpected error, 2 bad options / calibration, 3 input not found,
4 output error, 10 no camera, 11 unsupported camera mode, 12 camera lost,
13 camera not accessible, 14 no frame could be decoded.
)";

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "camera_driver: %s\n", message.c_str());
  return code;
}

int ListCameras() {
  std::string report;
  const int n = ListDc1394Cameras(&report);
  std::printf("IEEE 1394 cameras: %d\n%s", std::max(n, 0), report.c_str());
  std::printf("V4L2 devices:");
  bool any = false;
  for (int i = 0; i < 64; ++i) {
    const std::string path = "/dev/video" + std::to_string(i);
    if (std::FILE* f = std::fopen(path.c_str(), "r")) {
      std::fclose(f);
      std::printf(" %s", path.c_str());
      any = true;
    }
  }
  std::printf("%s\n", any ? "" : " none");
  return kExitOk;
}

int Main(int argc, char** argv) {
  CommandLine cl;
  const Status parsed = CommandLine::Parse(
      argc, argv, {"help", "reconnect", "list-cameras", "print-config", "no-progress", "quiet"},
      {"config", "source", "input", "log", "lcm-url", "calibration", "camera-name", "speed", "rate",
       "timestamps", "start-frame", "end-frame", "loops", "encoding", "color", "ground-truth",
       "gt-format", "device", "guid", "mode", "fps", "set", "log-level"},
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
  if (cl.Has("list-cameras")) return ListCameras();

  CameraDriverOptions options;
  if (cl.Has("config")) {
    const Status st = LoadOptionsFromFile(cl.Get("config"), &options);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  // Convenience flags are --set assignments applied in this order, then --set itself.
  const std::pair<const char*, const char*> kFlagToOption[] = {
      {"source", "source"}, {"input", "input"}, {"lcm-url", "lcm_url"},
      {"calibration", "calibration_file"}, {"camera-name", "camera_name"},
      {"speed", "playback.speed"}, {"rate", "folder.rate_hz"},
      {"timestamps", "folder.timestamps_file"}, {"start-frame", "playback.start_frame"},
      {"end-frame", "playback.end_frame"}, {"loops", "playback.loops"},
      {"encoding", "image.encoding"}, {"color", "image.color"},
      {"ground-truth", "ground_truth.file"}, {"gt-format", "ground_truth.format"},
      {"device", "v4l2.device"}, {"guid", "dc1394.guid"}, {"mode", "dc1394.video_mode"},
      {"fps", "dc1394.framerate"}, {"fps", "v4l2.fps"}};
  for (const auto& [flag, key] : kFlagToOption) {
    if (!cl.Has(flag)) continue;
    // Strings are quoted so that YAML does not reinterpret them (a GUID as a number).
    const std::string value = cl.Get(flag);
    const bool numeric = std::string(key).find("playback.") == 0 || std::string(key) == "folder.rate_hz" ||
                         std::string(key).find("framerate") != std::string::npos ||
                         std::string(key) == "v4l2.fps";
    std::string quoted = value;
    if (!numeric) {
      quoted = "'";
      for (char c : value) quoted += c == '\'' ? std::string("''") : std::string(1, c);
      quoted += "'";
    }
    const Status st = ApplyOptionAssignment(std::string(key) + "=" + quoted, &options);
    if (!st.ok()) return Fail(kExitUsage, "--" + std::string(flag) + ": " + st.message());
  }
  if (cl.Has("reconnect")) options.live.reconnect = true;
  if (cl.Has("no-progress")) options.playback.progress = false;
  for (const std::string& assignment : cl.GetAll("set")) {
    const Status st = ApplyOptionAssignment(assignment, &options);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  const std::string log_path = cl.Get("log");
  if (!log_path.empty() && options.playback.loops == 0 && !IsLiveCameraSource(options.source)) {
    return Fail(kExitUsage, "--log with playback.loops = 0 would never end; give a loop count");
  }
  if (cl.Has("print-config")) {
    std::cout << OptionsToYaml(options);
    return kExitOk;
  }
  if (!cl.Has("quiet")) {
    std::cout << "# camera_driver effective configuration\n" << OptionsToYaml(options) << std::flush;
  }

  InstallShutdownHandlers();
  std::unique_ptr<FrameSource> source = CreateFrameSource(options);
  Status sink_status;
  std::unique_ptr<MessageSink> sink = CreateMessageSink(log_path, options.lcm_url, &sink_status);
  if (!sink) return Fail(kExitOutputError, sink_status.message());

  CameraDriver driver(options, source.get(), sink.get());
  const SourceStatus result = driver.Run();
  source->Close();
  if (!result.ok()) {
    if (driver.stats().frames_published > 0) MBSLAM_LOG(INFO) << driver.Summary();
    // A log that got nothing is removed, so a failed conversion leaves no empty file.
    if (!log_path.empty() && sink->messages() == 0) {
      sink.reset();
      std::remove(log_path.c_str());
    }
    return Fail(ExitCodeFor(result.kind()), result.message());
  }
  if (driver.stats().frames_published > 0 || driver.stats().bad_frames > 0) {
    MBSLAM_LOG(INFO) << driver.Summary();
  }
  return kExitOk;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) {
  try {
    return mbslam::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "camera_driver: unexpected error: %s\n", e.what());
    return mbslam::kExitRuntimeError;
  }
}
