// perception_service: subscribes CAMERA_IMAGE / CAMERA_CALIBRATION / ODOMETRY, runs the
// multibody SLAM pipeline and publishes the PERCEPTION_* channels.
//
//   perception_service [--config FILE] [--lcm-url URL] [--mode realtime|lockstep]
//                      [--output-dir DIR] [--output-log FILE] [--set section.key=value ...]
//                      [--print-config]
//
// Replay a log deterministically:
//   perception_service --lcm-url 'file://seq.lcmlog?speed=0' --mode lockstep --output-log out.lcmlog

#include <cstdio>

#include <opencv2/core/utility.hpp>
#include <cstring>
#include <iostream>
#include <string>
#include <vector>

#include "common/config/options_yaml.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "services/perception/perception_options.h"
#include "services/perception/perception_service.h"

namespace mbslam {
namespace {

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;
constexpr int kExitLcm = 3;
constexpr int kExitOutput = 4;

void Usage() {
  std::fprintf(stderr,
               "usage: perception_service [--config FILE] [--lcm-url URL] [--mode realtime|lockstep]\n"
               "                          [--output-dir DIR] [--output-log FILE]\n"
               "                          [--set section.key=value ...] [--print-config]\n");
}

// "a.b.c=v" -> "a: {b: {c: v}}"
std::string OverrideToYaml(const std::string& assignment, bool* ok) {
  const size_t eq = assignment.find('=');
  *ok = eq != std::string::npos && eq > 0;
  if (!*ok) return "";
  std::string key = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);
  std::string yaml;
  int depth = 0;
  size_t start = 0;
  while (true) {
    const size_t dot = key.find('.', start);
    const std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
    if (dot == std::string::npos) {
      yaml += part + ": " + value;
      break;
    }
    yaml += part + ": {";
    ++depth;
    start = dot + 1;
  }
  yaml += std::string(static_cast<size_t>(depth), '}');
  return yaml;
}

int Run(int argc, char** argv) {
  InstallShutdownHandlers();
  // The pipeline has its own threads; OpenCV's worker pool on top of them would only
  // oversubscribe the cores and make timings (and floating-point reductions) vary.
  cv::setNumThreads(1);
  std::string config_path;
  std::vector<std::string> overrides;
  bool print_config = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    auto value = [&](const char* name) -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "perception_service: %s needs a value\n", name);
        std::exit(kExitUsage);
      }
      return argv[++i];
    };
    if (arg == "--config") config_path = value("--config");
    else if (arg == "--lcm-url") overrides.push_back("service.lcm_url=\"" + value("--lcm-url") + "\"");
    else if (arg == "--mode") overrides.push_back("pipeline.mode=" + value("--mode"));
    else if (arg == "--output-dir") overrides.push_back("service.output_dir=\"" + value("--output-dir") + "\"");
    else if (arg == "--output-log") overrides.push_back("service.output_log=\"" + value("--output-log") + "\"");
    else if (arg == "--set") overrides.push_back(value("--set"));
    else if (arg == "--print-config") print_config = true;
    else if (arg == "-h" || arg == "--help") {
      Usage();
      return kExitOk;
    } else {
      std::fprintf(stderr, "perception_service: unknown argument '%s'\n", arg.c_str());
      Usage();
      return kExitUsage;
    }
  }

  PerceptionOptions options;
  if (!config_path.empty()) {
    const Status s = LoadOptionsFromFile(config_path, &options);
    if (!s.ok()) {
      std::fprintf(stderr, "perception_service: %s\n", s.message().c_str());
      return kExitUsage;
    }
  }
  for (const std::string& o : overrides) {
    bool ok = false;
    const std::string yaml = OverrideToYaml(o, &ok);
    const Status s = ok ? LoadOptionsFromYamlText(yaml, "", &options)
                        : Status::Error("expected section.key=value");
    if (!s.ok()) {
      std::fprintf(stderr, "perception_service: bad override '%s': %s\n", o.c_str(), s.message().c_str());
      return kExitUsage;
    }
  }
  if (print_config) {
    std::cout << OptionsToYaml(options);
    return kExitOk;
  }
  LogLevel level = LogLevel::kInfo;
  ParseLogLevel(options.service.log_level, &level);
  SetLogLevel(level);
  std::cerr << "# perception_service effective configuration\n" << OptionsToYaml(options);

  Status status;
  auto service = PerceptionService::Create(options, &status);
  if (!service) {
    std::fprintf(stderr, "perception_service: %s\n", status.message().c_str());
    return kExitLcm;
  }
  const Status result = service->Run();
  return result.ok() ? kExitOk : kExitOutput;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) { return mbslam::Run(argc, argv); }
