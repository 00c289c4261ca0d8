#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_PAYLOADS_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_PAYLOADS_H_

// Plain measurement structs handed between the LCM adapters and the pipeline threads.
// No LCM types here: lcm_adapters/ converts messages into these.

#include <cstdint>
#include <memory>
#include <variant>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "services/perception/geometry/camera.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

enum class ImageEncoding { kGray8, kRgb8, kBgr8, kJpeg, kPng };

// One camera image as received: raw pixels or a compressed file, not yet decoded.
struct RawImage {
  int64_t utime = 0;           // exposure time (µs)
  int64_t seq = 0;             // driver sequence number
  int64_t receive_wall_utime = 0;  // wall clock at reception (µs), for latency only
  int width = 0;               // px
  int height = 0;              // px
  int row_stride = 0;          // bytes per row (raw encodings)
  ImageEncoding encoding = ImageEncoding::kGray8;
  std::vector<uint8_t> bytes;
  std::shared_ptr<const CameraIntrinsics> intrinsics;  // calibration valid for this image
  bool timeline_reset = false;  // time jumped back for good (replay loop, clock reset): start over
};

// A decoded image ready for the algorithms.
struct ImageFrame {
  int64_t utime = 0;               // exposure time (µs)
  int64_t seq = 0;                 // driver sequence number
  int64_t receive_wall_utime = 0;  // wall clock at reception (µs)
  cv::Mat gray;                    // CV_8UC1, width x height
  cv::Mat color;                   // CV_8UC3 BGR when the source had colour, else empty
  std::shared_ptr<const CameraIntrinsics> intrinsics;  // calibration valid for this image
  bool timeline_reset = false;     // see RawImage
};

// Robot odometry: odom_from_base with twist and covariance.
struct OdometrySample {
  int64_t utime = 0;              // µs
  Rigid3d odom_from_base;
  Vector6d twist_in_base = Vector6d::Zero();  // [v; w] in the base frame (m/s, rad/s)
  Matrix6d pose_covariance = Matrix6d::Zero();  // [t; r] order (m^2, rad^2); zero = unknown
};

// What the input side hands to the pipeline, in arrival order.
using InputEvent = std::variant<RawImage, OdometrySample>;

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_PAYLOADS_H_
