// viewer: offscreen OSMesa renderer of the perception outputs. Subscribes to
// PERCEPTION_CAMERA_POSE, PERCEPTION_OBJECTS, PERCEPTION_MAP, PERCEPTION_OCCUPANCY,
// PERCEPTION_TRACKS, CAMERA_IMAGE and SNAPSHOT_REQUEST and writes PNG snapshots of the
// 3D map view and of the image view every N seconds of message time, on request, and
// at exit.
//
//   viewer [--config FILE] [--lcm-url URL] [--out DIR] [--set section.key=value ...]
//          [--print-config]
//
// Render a log deterministically:
//   viewer --lcm-url 'file://out.lcmlog?speed=0' --out out/viewer

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "common/config/options_yaml.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "viewer/viewer_app.h"
#include "viewer/viewer_options.h"

namespace mbslam {
namespace viewer {
namespace {

constexpr int kExitOk = 0;
constexpr int kExitUsage = 2;
constexpr int kExitStartup = 3;
constexpr int kExitOutput = 4;

void Usage() {
  std::fprintf(stderr,
               "usage: viewer [--config FILE] [--lcm-url URL] [--out DIR]\n"
               "              [--set section.key=value ...] [--print-config]\n"
               "  --lcm-url  e.g. 'file://run.lcmlog?speed=0' (deterministic replay) or\n"
               "             'udpm://239.255.76.67:7667?ttl=0' (live)\n"
               "  --out      snapshot directory (viewer.output_dir)\n"
               "  --set      any option, e.g. --set view3d.camera_mode=top_down\n");
}

// "a.b.c=value" applied to the options: the value is parsed as YAML (numbers, lists,
// strings), nested under the dotted key.
Status ApplyOverride(const std::string& assignment, ViewerOptions* options) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) return Status::Error("expected section.key=value");
  std::vector<std::string> keys;
  size_t start = 0;
  const std::string key = assignment.substr(0, eq);
  while (true) {
    const size_t dot = key.find('.', start);
    keys.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  for (const std::string& k : keys) {
    if (k.empty()) return Status::Error("empty key in '" + key + "'");
  }
  YAML::Node node;
  try {
    node = YAML::Load(assignment.substr(eq + 1));
  } catch (const YAML::Exception& e) {
    return Status::Error(std::string("bad value: ") + e.what());
  }
  for (auto it = keys.rbegin(); it != keys.rend(); ++it) {
    YAML::Node parent(YAML::NodeType::Map);
    parent[*it] = node;
    node = parent;
  }
  return LoadOptionsFromYaml(node, "", options);
}

int Run(int argc, char** argv) {
  InstallShutdownHandlers();
  std::string config_path, lcm_url, out_dir;
  bool have_url = false, have_out = false, print_config = false;
  std::vector<std::string> overrides;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if ((arg == "--config" || arg == "--lcm-url" || arg == "--out" || arg == "--set") &&
        !has_value) {
      std::fprintf(stderr, "viewer: %s needs a value\n", arg.c_str());
      return kExitUsage;
    }
    if (arg == "--config") {
      config_path = argv[++i];
    } else if (arg == "--lcm-url") {
      lcm_url = argv[++i];
      have_url = true;
    } else if (arg == "--out") {
      out_dir = argv[++i];
      have_out = true;
    } else if (arg == "--set") {
      overrides.push_back(argv[++i]);
    } else if (arg == "--print-config") {
      print_config = true;
    } else if (arg == "-h" || arg == "--help") {
      Usage();
      return kExitOk;
    } else {
      std::fprintf(stderr, "viewer: unknown argument '%s'\n", arg.c_str());
      Usage();
      return kExitUsage;
    }
  }

  ViewerOptions options;
  if (!config_path.empty()) {
    const Status s = LoadOptionsFromFile(config_path, &options);
    if (!s.ok()) {
      std::fprintf(stderr, "viewer: %s\n", s.message().c_str());
      return kExitUsage;
    }
  }
  for (const std::string& o : overrides) {
    const Status s = ApplyOverride(o, &options);
    if (!s.ok()) {
      std::fprintf(stderr, "viewer: bad --set '%s': %s\n", o.c_str(), s.message().c_str());
      return kExitUsage;
    }
  }
  if (have_url) options.viewer.lcm_url = lcm_url;
  if (have_out) options.viewer.output_dir = out_dir;
  if (!options.Check()) {
    std::fprintf(stderr, "viewer: %s\n", LastOptionError().c_str());
    return kExitUsage;
  }
  if (print_config) {
    std::cout << "# viewer configuration: every option with its value (the defaults unless\n"
                 "# --config / --set changed them). Regenerate config/viewer.yaml with:\n"
                 "#   viewer --print-config > config/viewer.yaml\n"
                 "# Override any value on the command line with --set section.key=value.\n"
              << OptionsToYaml(options);
    return kExitOk;
  }
  LogLevel level = LogLevel::kInfo;
  ParseLogLevel(options.viewer.log_level, &level);
  SetLogLevel(level);
  std::cerr << "# viewer effective configuration\n" << OptionsToYaml(options);

  Status status;
  auto app = ViewerApp::Create(options, &status);
  if (!app) {
    std::fprintf(stderr, "viewer: %s\n", status.message().c_str());
    return kExitStartup;
  }
  const Status result = app->Run();
  if (!result.ok()) {
    std::fprintf(stderr, "viewer: %s\n", result.message().c_str());
    return kExitOutput;
  }
  return kExitOk;
}

}  // namespace
}  // namespace viewer
}  // namespace mbslam

int main(int argc, char** argv) { return mbslam::viewer::Run(argc, argv); }
