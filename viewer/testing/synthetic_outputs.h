#ifndef MBSLAM_VIEWER_TESTING_SYNTHETIC_OUTPUTS_H_
#define MBSLAM_VIEWER_TESTING_SYNTHETIC_OUTPUTS_H_

// A synthetic run of the perception service's outputs, for the viewer's tests and demo:
// a camera driving forward down a street (ground plane, two facades, a few posts), two
// moving objects (one crossing, one driving ahead in the camera's direction: the
// degenerate case for the epipolar constraint), their particles and predicted volumes,
// an OctoMap of the static points, feature tracks with labels, flow and hulls, and the
// camera images (raw BGR, or JPEG). All in the SLAM frame (x right, y down, z forward),
// ground plane at y = 1.5, up-to-scale or metric.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/util/status.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/map_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "mbslam/tracks_t.hpp"

namespace mbslam {
namespace viewer {
namespace testing {

struct SyntheticOptions {
  int width = 640;                // image width (px)
  int height = 480;               // image height (px)
  double fps = 10.0;              // frame rate (Hz)
  int frames = 40;                // frames in a log (count)
  int map_every = 5;              // a map_t and an occupancy_t every this many frames (count)
  bool jpeg = false;              // images as JPEG instead of raw BGR
  bool metric = true;             // scale_state METRIC (else up to scale)
  int64_t start_utime = 1000000;  // time of frame 0 (µs)
  uint32_t seed = 7;
};

struct SyntheticFrame {
  int64_t utime = 0;
  mbslam::image_t image{};
  mbslam::camera_pose_t pose{};
  mbslam::tracks_t tracks{};
  mbslam::objects_t objects{};
  std::optional<mbslam::map_t> map;
  std::optional<mbslam::occupancy_t> occupancy;
};

class SyntheticOutputs {
 public:
  explicit SyntheticOutputs(const SyntheticOptions& options = SyntheticOptions());

  SyntheticFrame Frame(int k) const;

  // Camera centre at frame k (world, units).
  static double CameraZ(double t_s) { return 1.2 * t_s; }
  const SyntheticOptions& options() const { return options_; }
  const std::vector<std::array<float, 3>>& static_points() const { return static_points_; }

 private:
  SyntheticOptions options_;
  std::vector<std::array<float, 3>> static_points_;
  std::vector<std::array<uint8_t, 3>> static_colors_;
};

// Writes frames 0..frames-1 to an LCM log (each frame: image, pose, tracks, objects and,
// every map_every frames, map and occupancy), stamped with message time. With
// `faults`, malformed messages are mixed in on several channels.
Status WriteSyntheticLog(const std::string& path, const SyntheticOptions& options,
                         const ChannelOptions& channels, bool faults, int* bad_messages_written);

}  // namespace testing
}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_TESTING_SYNTHETIC_OUTPUTS_H_
