#ifndef MBSLAM_TOOLS_SIM_SEQUENCE_WRITER_H_
#define MBSLAM_TOOLS_SIM_SEQUENCE_WRITER_H_

// Writes a simulated sequence as the sequence folder of tools/sim/SEQUENCE_FORMAT.md and
// as an LCM log (sequence.lcmlog) with the project's message types.

#include <functional>
#include <string>
#include <vector>

#include "common/config/options.h"
#include "common/lcm/channels.h"
#include "common/util/status.h"
#include "tools/sim/simulator.h"

namespace mbslam {
namespace sim {

struct SequenceWriterOptions {
  bool write_files = true;    // images/, masks/, depth/, trajectories, yaml files
  bool write_masks = true;    // masks/ (16-bit PNG)
  bool write_depth = true;    // depth/
  bool write_points = true;   // points/<body id>.txt
  bool write_lcm = true;      // sequence.lcmlog
  bool color_images = false;  // images/ in BGR (else grey)
  std::string depth_format =
      "exr";  // "exr" (32-bit float, m) or "png" (16-bit, mm; 0 = none or > 65.535 m)
  std::string exr_compression =
      "rle";  // none | rle | zip (zip: ~half the size, ~3x slower to write)
  std::string lcm_image_encoding = "gray8";  // image_t encoding: gray8 | bgr8 | png | jpeg
  int jpeg_quality = 95;                     // for lcm_image_encoding jpeg (0-100)
  double calibration_period_s = 1.0;  // CAMERA_CALIBRATION on the first image, then every this (s)
  ChannelOptions channels;            // LCM channel names

  bool Check() const {
    MBSLAM_CHECK_OPTION(depth_format == "exr" || depth_format == "png");
    MBSLAM_CHECK_OPTION(exr_compression == "none" || exr_compression == "rle" ||
                        exr_compression == "zip");
    MBSLAM_CHECK_OPTION(lcm_image_encoding == "gray8" || lcm_image_encoding == "bgr8" ||
                        lcm_image_encoding == "png" || lcm_image_encoding == "jpeg");
    MBSLAM_CHECK_OPTION_GE(jpeg_quality, 0);
    MBSLAM_CHECK_OPTION_LE(jpeg_quality, 100);
    MBSLAM_CHECK_OPTION_GT(calibration_period_s, 0.0);
    MBSLAM_CHECK_OPTION(channels.Check());
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("write_files", &write_files, "images/, masks/, depth/, trajectories, yaml files");
    v("write_masks", &write_masks, "masks/ (16-bit PNG)");
    v("write_depth", &write_depth, "depth/");
    v("write_points", &write_points, "points/<body id>.txt");
    v("write_lcm", &write_lcm, "sequence.lcmlog");
    v("color_images", &color_images, "images/ in BGR (else grey)");
    v("depth_format", &depth_format, "exr (float, m) or png (16-bit, mm)");
    v("exr_compression", &exr_compression, "none | rle | zip");
    v("lcm_image_encoding", &lcm_image_encoding, "image_t encoding: gray8 | bgr8 | png | jpeg");
    v("jpeg_quality", &jpeg_quality, "for lcm_image_encoding jpeg (0-100)");
    v("calibration_period_s", &calibration_period_s,
      "CAMERA_CALIBRATION period after the first image (s)");
    v("channels", &channels, "LCM channel names");
  }
};

struct SequenceSummary {
  int frames = 0;
  double render_seconds = 0.0;        // time spent rendering (s, wall clock)
  double total_seconds = 0.0;         // rendering and writing (s, wall clock)
  double mean_moving_fraction = 0.0;  // of the image covered by moving bodies, mean over frames
  double min_moving_fraction = 0.0;
  double max_moving_fraction = 0.0;
  std::vector<int> frames_visible;  // per moving body (ascending id): frames with >= 1 pixel
  int64_t lcm_events = 0;
  int odometry_samples = 0;
};

// Renders every frame of `sim` and writes the sequence into `dir` (created if needed).
// `progress(k)` is called after frame k.
Status WriteSequence(Simulator* sim, const std::string& dir, const SequenceWriterOptions& options,
                     SequenceSummary* summary, const std::function<void(int)>& progress = nullptr);

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_SEQUENCE_WRITER_H_
