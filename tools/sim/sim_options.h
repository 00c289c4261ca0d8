#ifndef MBSLAM_TOOLS_SIM_SIM_OPTIONS_H_
#define MBSLAM_TOOLS_SIM_SIM_OPTIONS_H_

// Options of the synthetic multibody scene simulator (one struct, nested sections).

#include <cstdint>
#include <string>

#include "common/config/options.h"
#include "services/perception/geometry/camera.h"
#include "tools/sim/renderer.h"

namespace mbslam {
namespace sim {

struct SimCameraOptions {
  std::string name = "sim";  // camera_name in calibration and image messages
  int width = 640;           // image width (px)
  int height = 480;          // image height (px)
  double fx = 0.0;           // focal length x (px); 0 = 525 * width / 640
  double fy = 0.0;           // focal length y (px); 0 = 525 * width / 640
  double cx = -1.0;          // principal point x (px); negative = (width - 1) / 2
  double cy = -1.0;          // principal point y (px); negative = (height - 1) / 2

  // The pinhole intrinsics these options describe (no distortion).
  CameraIntrinsics Intrinsics() const;

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(width, 16);
    MBSLAM_CHECK_OPTION_GE(height, 16);
    MBSLAM_CHECK_OPTION_LE(width, 8192);
    MBSLAM_CHECK_OPTION_LE(height, 8192);
    MBSLAM_CHECK_OPTION_GE(fx, 0.0);
    MBSLAM_CHECK_OPTION_GE(fy, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("name", &name, "camera_name in calibration and image messages");
    v("width", &width, "image width (px)");
    v("height", &height, "image height (px)");
    v("fx", &fx, "focal length x (px); 0 = 525 * width / 640");
    v("fy", &fy, "focal length y (px); 0 = 525 * width / 640");
    v("cx", &cx, "principal point x (px); negative = (width - 1) / 2");
    v("cy", &cy, "principal point y (px); negative = (height - 1) / 2");
  }
};

struct SimImageOptions {
  double noise_sigma = 0.0;     // Gaussian pixel noise, standard deviation (grey levels)
  int motion_blur_samples = 1;  // sub-frames averaged over the exposure; 1 = no blur (count)
  double exposure_ms = 12.0;    // exposure time used for motion blur (ms)
  RendererOptions render;       // renderer settings

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(noise_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(motion_blur_samples, 1);
    MBSLAM_CHECK_OPTION_LE(motion_blur_samples, 64);
    MBSLAM_CHECK_OPTION_GE(exposure_ms, 0.0);
    MBSLAM_CHECK_OPTION_SECTION(render);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("noise_sigma", &noise_sigma, "Gaussian pixel noise, standard deviation (grey levels)");
    v("motion_blur_samples", &motion_blur_samples,
      "sub-frames averaged over the exposure; 1 = off (count)");
    v("exposure_ms", &exposure_ms, "exposure time used for motion blur (ms)");
    v("render", &render, "renderer settings");
  }
};

// Wheel odometry of the robot carrying the camera (scenarios with a robot base). The
// measured forward speed and yaw rate get a constant scale error, a yaw-rate bias and
// white noise, and are integrated into a drifting odom_from_base.
struct SimOdometryOptions {
  double rate_hz = 50.0;          // sample rate (Hz)
  int64_t time_offset_us = 3000;  // time of the first sample after the first image (µs)
  double speed_scale_error =
      0.015;  // relative error of the measured speed (fraction; sign from the seed)
  double yaw_rate_scale_error = 0.02;  // relative error of the measured yaw rate (fraction)
  double yaw_rate_bias = 0.004;        // constant yaw-rate bias (rad/s)
  double speed_noise = 0.02;           // white noise on each speed sample (m/s)
  double yaw_rate_noise = 0.01;        // white noise on each yaw-rate sample (rad/s)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(rate_hz, 0.0);
    MBSLAM_CHECK_OPTION_LE(rate_hz, 1000.0);
    MBSLAM_CHECK_OPTION_GE(time_offset_us, 0);
    MBSLAM_CHECK_OPTION_GE(speed_scale_error, 0.0);
    MBSLAM_CHECK_OPTION_GE(yaw_rate_scale_error, 0.0);
    MBSLAM_CHECK_OPTION_GE(speed_noise, 0.0);
    MBSLAM_CHECK_OPTION_GE(yaw_rate_noise, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("rate_hz", &rate_hz, "sample rate (Hz)");
    v("time_offset_us", &time_offset_us, "time of the first sample after the first image (µs)");
    v("speed_scale_error", &speed_scale_error, "relative error of the measured speed (fraction)");
    v("yaw_rate_scale_error", &yaw_rate_scale_error,
      "relative error of the measured yaw rate (fraction)");
    v("yaw_rate_bias", &yaw_rate_bias, "constant yaw-rate bias (rad/s)");
    v("speed_noise", &speed_noise, "white noise on each speed sample (m/s)");
    v("yaw_rate_noise", &yaw_rate_noise, "white noise on each yaw-rate sample (rad/s)");
  }
};

struct SimOptions {
  std::string scenario = "static";         // one of ScenarioNames()
  int64_t seed = 1;                        // seed of everything random (world, textures, noise)
  int num_frames = 300;                    // images in the sequence (count)
  double fps = 30.0;                       // image rate (Hz)
  int64_t start_utime = 1600000000000000;  // time of the first image (µs)
  double texel_m = 0.006;                  // texel size of surfaces near the camera at fx = 525 (m)
  double lod_distance_m = 6.0;  // texel size grows beyond this distance from the camera path (m)
  int max_texture_px = 1024;    // largest texture side (px)
  double static_points_per_m2 =
      20.0;  // ground-truth samples of the static world near the camera path (1/m^2)
  double object_points_per_m2 = 400.0;  // ground-truth surface samples of moving objects (1/m^2)
  int max_points_per_body = 60000;      // cap on ground-truth samples per body (count)
  SimCameraOptions camera;              // camera model and image size
  SimImageOptions image;                // noise, blur, rendering
  SimOdometryOptions odometry;          // wheel odometry (robot scenarios)

  // Time of image k (µs).
  int64_t FrameUtime(int k) const;

  bool Check() const {
    MBSLAM_CHECK_OPTION(!scenario.empty());
    MBSLAM_CHECK_OPTION_GE(seed, 0);
    MBSLAM_CHECK_OPTION_GE(num_frames, 1);
    MBSLAM_CHECK_OPTION_LE(num_frames, 100000);
    MBSLAM_CHECK_OPTION_GT(fps, 0.0);
    MBSLAM_CHECK_OPTION_LE(fps, 1000.0);
    MBSLAM_CHECK_OPTION_GT(texel_m, 0.0);
    MBSLAM_CHECK_OPTION_GT(lod_distance_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_texture_px, 16);
    MBSLAM_CHECK_OPTION_LE(max_texture_px, 8192);
    MBSLAM_CHECK_OPTION_GE(static_points_per_m2, 0.0);
    MBSLAM_CHECK_OPTION_GE(object_points_per_m2, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_points_per_body, 1);
    MBSLAM_CHECK_OPTION_SECTION(camera);
    MBSLAM_CHECK_OPTION_SECTION(image);
    MBSLAM_CHECK_OPTION_SECTION(odometry);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("scenario", &scenario, "scenario name (mbslam-sim --list)");
    v("seed", &seed, "seed of everything random");
    v("num_frames", &num_frames, "images in the sequence (count)");
    v("fps", &fps, "image rate (Hz)");
    v("start_utime", &start_utime, "time of the first image (µs)");
    v("texel_m", &texel_m, "texel size of surfaces near the camera at fx = 525 (m)");
    v("lod_distance_m", &lod_distance_m,
      "texel size grows beyond this distance from the camera path (m)");
    v("max_texture_px", &max_texture_px, "largest texture side (px)");
    v("static_points_per_m2", &static_points_per_m2,
      "ground-truth samples of the static world near the camera path, fewer with distance (1/m^2)");
    v("object_points_per_m2", &object_points_per_m2,
      "ground-truth samples of moving objects (1/m^2)");
    v("max_points_per_body", &max_points_per_body, "cap on ground-truth samples per body (count)");
    v("camera", &camera, "camera model and image size");
    v("image", &image, "noise, blur, rendering");
    v("odometry", &odometry, "wheel odometry (robot scenarios)");
  }
};

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_SIM_OPTIONS_H_
