// mbslam-sim: generates a synthetic multibody sequence (sequence folder + LCM log) and
// checks the consistency of its ground truth.
//
//   mbslam-sim --list
//   mbslam-sim --scenario crossing --out out/crossing [--frames 300] [--size 640x480]
//   mbslam-sim --scenario multi --check --check-frames 10 --size 320x240
//
// Prints a human summary and, as the last line, one JSON object.

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <optional>
#include <string>

#include "common/config/options_yaml.h"
#include "common/util/atomic_file.h"
#include "common/util/command_line.h"
#include "common/util/logging.h"
#include "common/util/time.h"
#include "tools/sim/gt_check.h"
#include "tools/sim/scenarios.h"
#include "tools/sim/sequence_writer.h"
#include "tools/sim/simulator.h"

namespace {

using mbslam::Status;
namespace sim = mbslam::sim;

void Usage() {
  std::cerr <<
      R"(usage: mbslam-sim --scenario NAME [options]
  --list                  list the scenarios and exit
  --scenario NAME         scenario to generate (see --list)
  --out DIR               write the sequence folder and DIR/sequence.lcmlog
  --config FILE           simulator options (YAML, keys as in --print-config)
  --print-config          print the effective simulator options and exit
  --frames N              number of images (default 300)
  --size WxH              image size (default 640x480; intrinsics scale with the width)
  --fps F                 image rate (Hz, default 30)
  --seed S                seed (default 1)
  --noise SIGMA           Gaussian image noise (grey levels, default 0)
  --blur N                motion blur sub-frames (default 1 = off)
  --color                 images/ in BGR (default grey)
  --depth exr|png         depth format (default exr)
  --image-encoding E      image_t encoding in the log: gray8|bgr8|png|jpeg (default gray8)
  --no-files              only the LCM log
  --no-lcm                only the files
  --check                 ground-truth consistency check (no --out needed)
  --check-frames N        frames checked, evenly spread (default 10)
  --json FILE             also write the final JSON object to FILE
  --quiet                 less logging and no human summary
  --verbose               debug logging
)";
}

bool g_quiet = false;

// The human summary (suppressed by --quiet).
void Say(const char* format, ...) __attribute__((format(printf, 1, 2)));
void Say(const char* format, ...) {
  if (g_quiet) {
    return;
  }
  va_list args;
  va_start(args, format);
  std::vprintf(format, args);
  va_end(args);
}

}  // namespace

static int Main(int argc, char** argv) {
  sim::SimOptions options;
  sim::SequenceWriterOptions writer;
  std::string out_dir, config, json_file;
  bool list = false, check = false, print_config = false, quiet = false;
  int check_frames = 10;
  // Command-line overrides, applied after the config file.
  std::string scenario, size;
  // Given on the command line: applied as given (the options' Check() refuses bad values).
  std::optional<int> frames, blur;
  std::optional<double> fps, noise;
  std::optional<int64_t> seed;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "mbslam-sim: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    // Numbers are read whole: "--frames 30x" or "--fps abc" is an error, not 30 or 0.
    auto next_int = [&]() -> int64_t {
      const std::string text = next();
      int64_t v = 0;
      const Status st = mbslam::ParseInt64(text, a, &v);
      if (!st.ok()) {
        std::cerr << "mbslam-sim: " << st.message() << "\n";
        std::exit(2);
      }
      return v;
    };
    auto next_count = [&]() -> int {
      const int64_t v = next_int();
      if (v < 0 || v > std::numeric_limits<int>::max()) {
        std::cerr << "mbslam-sim: " << a << " " << v << " is out of range\n";
        std::exit(2);
      }
      return static_cast<int>(v);
    };
    auto next_double = [&]() -> double {
      double v = 0.0;
      const Status st = mbslam::ParseDouble(next(), a, &v);
      if (!st.ok()) {
        std::cerr << "mbslam-sim: " << st.message() << "\n";
        std::exit(2);
      }
      return v;
    };
    if (a == "--list") {
      list = true;
    } else if (a == "--scenario") {
      scenario = next();
    } else if (a == "--out") {
      out_dir = next();
    } else if (a == "--config") {
      config = next();
    } else if (a == "--print-config") {
      print_config = true;
    } else if (a == "--frames") {
      frames = next_count();
    } else if (a == "--size") {
      size = next();
    } else if (a == "--fps") {
      fps = next_double();
    } else if (a == "--seed") {
      seed = next_int();
      if (*seed < 0) {
        std::cerr << "mbslam-sim: --seed " << *seed << " is negative\n";
        return 2;
      }
    } else if (a == "--noise") {
      noise = next_double();
    } else if (a == "--blur") {
      blur = next_count();
    } else if (a == "--color") {
      writer.color_images = true;
    } else if (a == "--depth") {
      writer.depth_format = next();
    } else if (a == "--image-encoding") {
      writer.lcm_image_encoding = next();
    } else if (a == "--no-files") {
      writer.write_files = false;
    } else if (a == "--no-lcm") {
      writer.write_lcm = false;
    } else if (a == "--check") {
      check = true;
    } else if (a == "--check-frames") {
      check_frames = next_count();
    } else if (a == "--quiet") {
      quiet = true;
    } else if (a == "--verbose") {
      mbslam::SetLogLevel(mbslam::LogLevel::kDebug);
    } else if (a == "--json") {
      json_file = next();
    } else if (a == "-h" || a == "--help") {
      Usage();
      return 0;
    } else {
      std::cerr << "mbslam-sim: unknown argument '" << a << "'\n";
      Usage();
      return 2;
    }
  }
  g_quiet = quiet;
  if (quiet) {
    mbslam::SetLogLevel(mbslam::LogLevel::kWarning);
  }
  if (list) {
    for (const auto& n : sim::ScenarioNames()) {
      std::printf("  %-18s %s\n", n.c_str(), sim::ScenarioDescription(n).c_str());
    }
    return 0;
  }
  if (!config.empty()) {
    const Status st = mbslam::LoadOptionsFromFile(config, &options);
    if (!st.ok()) {
      std::cerr << "mbslam-sim: " << st.message() << "\n";
      return 2;
    }
  }
  if (!scenario.empty()) {
    options.scenario = scenario;
  }
  if (frames) options.num_frames = *frames;
  if (fps) options.fps = *fps;
  if (seed) options.seed = *seed;
  if (noise) options.image.noise_sigma = *noise;
  if (blur) options.image.motion_blur_samples = *blur;
  if (!size.empty()) {
    const Status st = mbslam::ParseImageSize(size, "--size", &options.camera.width, &options.camera.height);
    if (!st.ok()) {
      std::cerr << "mbslam-sim: " << st.message() << "\n";
      return 2;
    }
  }
  if (!options.Check()) {
    std::cerr << "mbslam-sim: " << mbslam::LastOptionError() << "\n";
    return 2;
  }
  if (!writer.Check()) {
    std::cerr << "mbslam-sim: " << mbslam::LastOptionError() << "\n";
    return 2;
  }
  if (print_config) {
    std::cout << mbslam::OptionsToYaml(options);
    return 0;
  }
  if (out_dir.empty() && !check) {
    std::cerr << "mbslam-sim: nothing to do (give --out DIR and/or --check)\n";
    Usage();
    return 2;
  }

  const int64_t t0 = mbslam::MonotonicUtime();
  Status status;
  auto simulator = sim::Simulator::Create(options, &status);
  if (!simulator) {
    std::cerr << "mbslam-sim: " << status.message() << "\n";
    return 1;
  }
  const double setup_s = 1e-6 * static_cast<double>(mbslam::MonotonicUtime() - t0);
  const auto& K = simulator->intrinsics();
  MBSLAM_LOG(INFO) << "scenario " << options.scenario << ": " << simulator->MovingBodyIds().size()
                   << " moving bodies, " << options.num_frames << " frames at " << K.width << "x"
                   << K.height << ", set-up " << setup_s << " s";

  std::string json = "{\"scenario\": \"" + options.scenario +
                     "\", \"frames\": " + std::to_string(options.num_frames) +
                     ", \"width\": " + std::to_string(K.width) +
                     ", \"height\": " + std::to_string(K.height) +
                     ", \"setup_s\": " + std::to_string(setup_s);
  if (!out_dir.empty()) {
    sim::SequenceSummary summary;
    status = sim::WriteSequence(simulator.get(), out_dir, writer, &summary, [&](int k) {
      if ((k + 1) % 50 == 0) {
        MBSLAM_LOG(INFO) << "frame " << k + 1 << " / " << options.num_frames;
      }
    });
    if (!status.ok()) {
      std::cerr << "mbslam-sim: " << status.message() << "\n";
      return 1;
    }
    const double fps_render =
        summary.render_seconds > 0 ? summary.frames / summary.render_seconds : 0.0;
    const double fps_total =
        summary.total_seconds > 0 ? summary.frames / summary.total_seconds : 0.0;
    Say("wrote %d frames of '%s' to %s\n", summary.frames, options.scenario.c_str(),
        out_dir.c_str());
    Say("  rendering: %.1f frames/s; rendering + writing: %.1f frames/s; set-up %.2f s\n",
        fps_render, fps_total, setup_s);
    Say("  image covered by moving bodies: mean %.1f %%, min %.1f %%, max %.1f %%\n",
        100.0 * summary.mean_moving_fraction, 100.0 * summary.min_moving_fraction,
        100.0 * summary.max_moving_fraction);
    std::string visible = "[";
    for (size_t i = 0; i < summary.frames_visible.size(); ++i) {
      visible += (i ? ", " : "") + std::to_string(summary.frames_visible[i]);
    }
    visible += "]";
    Say("  frames in which each mover is visible: %s\n", visible.c_str());
    if (summary.odometry_samples > 0) {
      Say("  odometry samples: %d\n", summary.odometry_samples);
    }
    json += ", \"out\": \"" + out_dir + "\", \"render_fps\": " + std::to_string(fps_render) +
            ", \"total_fps\": " + std::to_string(fps_total) +
            ", \"mean_moving_fraction\": " + std::to_string(summary.mean_moving_fraction) +
            ", \"min_moving_fraction\": " + std::to_string(summary.min_moving_fraction) +
            ", \"frames_visible\": " + visible +
            ", \"lcm_events\": " + std::to_string(summary.lcm_events) +
            ", \"odometry_samples\": " + std::to_string(summary.odometry_samples);
  }
  if (check) {
    sim::GtCheckOptions check_options;
    sim::GtCheckReport report;
    sim::SimFrame frame;
    const int n = std::max(1, std::min(check_frames, options.num_frames));
    for (int i = 0; i < n; ++i) {
      const int k =
          n == 1 ? 0
                 : static_cast<int>(static_cast<int64_t>(i) * (options.num_frames - 1) / (n - 1));
      status = simulator->RenderFrame(k, &frame, sim::RenderRequest{false, true});
      if (status.ok()) {
        status = sim::CheckFrameGroundTruth(*simulator, frame, check_options, &report);
      }
      if (!status.ok()) {
        std::cerr << "mbslam-sim: " << status.message() << "\n";
        return 1;
      }
    }
    Say("ground-truth check of '%s' over %d frames:\n", options.scenario.c_str(), report.frames);
    Say("  visible surface samples: %lld (%lld on movers), label error max %.4f px, failures "
        "%lld\n",
        static_cast<long long>(report.samples_visible),
        static_cast<long long>(report.samples_visible_moving), report.label_max_px,
        static_cast<long long>(report.label_failures));
    Say("  sub-pixel reprojection of samples: max %.5f px, rms %.5f px (%lld samples)\n",
        report.reprojection_max_px, report.reprojection_rms_px,
        static_cast<long long>(report.reprojection_samples));
    Say("  pixels vs ray casts: %lld, label mismatches %lld (%lld on silhouettes), depth error max "
        "%.2e m "
        "(rel %.2e)\n",
        static_cast<long long>(report.pixels),
        static_cast<long long>(report.pixel_label_mismatches),
        static_cast<long long>(report.pixel_label_mismatches_on_edges),
        report.depth_max_abs_error_m, report.depth_max_rel_error);
    json += ", \"check\": " + report.ToJson();
  }
  json += "}";
  if (!json_file.empty()) {
    status = mbslam::WriteStringAtomically(json_file, json + "\n");
    if (!status.ok()) {
      std::cerr << "mbslam-sim: " << status.message() << "\n";
      return 1;
    }
  }
  if (!quiet) {
    std::cout << json << std::endl;
  }
  return 0;
}

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "mbslam-sim: " << e.what() << "\n";
    return 1;
  }
}
