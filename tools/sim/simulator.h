#ifndef MBSLAM_TOOLS_SIM_SIMULATOR_H_
#define MBSLAM_TOOLS_SIM_SIMULATOR_H_

// The in-memory API of the synthetic multibody scene simulator:
//
//   sim::SimOptions options;
//   options.scenario = "crossing";
//   options.num_frames = 30;
//   options.camera.width = 320; options.camera.height = 240;
//   Status status;
//   auto sim = sim::Simulator::Create(options, &status);
//   sim::SimFrame frame;
//   status = sim->RenderFrame(7, &frame);   // image, mask, depth, poses of frame 7
//
// Every frame is a pure function of (options, frame index): frames can be rendered in any
// order, and the same options give the same pixels (on the same machine: llvmpipe's
// results may differ in the last bit between CPUs). Conventions: world z up, ground
// z = 0, metres; poses world_from_x; time int64 µs; body id 0 = static world.
//
// A Simulator owns an OSMesa GL context: use it from one thread at a time, and do not
// keep it in static storage (a context destroyed during static destruction, after the
// driver has shut down, crashes). Creation builds the textures (a few seconds at
// 640x480, less for smaller images).

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "services/perception/geometry/camera.h"
#include "services/perception/geometry/rigid3.h"
#include "tools/sim/renderer.h"
#include "tools/sim/scene.h"
#include "tools/sim/sim_options.h"

namespace mbslam {
namespace sim {

// Ground truth of one moving body at one image.
struct SimBodyState {
  int id = 0;        // mask value (> 0)
  std::string name;  // "car", "person", "robot", "box"
  Eigen::Vector3d extent =
      Eigen::Vector3d::Zero();  // full box size along body x, y, z (m); origin at its centre
  Rigid3d world_from_body;
  Eigen::Vector3d linear_velocity =
      Eigen::Vector3d::Zero();  // of the body origin, world frame (m/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame (rad/s)
  int pixel_count = -1;  // pixels with this id in the mask; -1 if the mask was not rendered
  bool visible = false;  // pixel_count > 0 (false if not rendered)
};

struct SimFrame {
  int index = 0;
  int64_t utime = 0;       // time of the image (centre of exposure) (µs)
  Rigid3d world_from_cam;  // camera axes x right, y down, z forward
  Eigen::Vector3d cam_linear_velocity = Eigen::Vector3d::Zero();   // world frame (m/s)
  Eigen::Vector3d cam_angular_velocity = Eigen::Vector3d::Zero();  // world frame (rad/s)
  std::vector<SimBodyState> bodies;  // every moving body, ascending id
  cv::Mat image_bgr;                 // CV_8UC3
  cv::Mat image_gray;                // CV_8UC1 (from the same render, own noise draw)
  cv::Mat mask;                      // CV_16UC1 body id per pixel (0 = static world and sky)
  cv::Mat depth;                     // CV_32FC1 z along the optical axis (m); 0 = no surface (sky)
  cv::Mat points_in_cam;  // CV_32FC3 surface point at each pixel centre, camera frame (m)

  // Fraction of the pixels that belong to moving bodies (needs the mask).
  double MovingFraction() const;
};

// What RenderFrame produces (poses and velocities are always filled).
struct RenderRequest {
  bool image = true;     // image_bgr and image_gray
  bool geometry = true;  // mask, depth, points_in_cam, pixel counts
};

// One wheel-odometry sample of the robot base (robot scenarios).
struct OdometrySample {
  int64_t utime = 0;
  int64_t seq = 0;
  Rigid3d odom_from_base;  // odom frame = base pose at the first sample
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // base frame (m/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // base frame (rad/s)
  Matrix6d pose_covariance = Matrix6d::Zero();                 // [x y z rx ry rz] (m^2, rad^2)
  Matrix6d twist_covariance = Matrix6d::Zero();  // [vx vy vz wx wy wz] (m^2/s^2, rad^2/s^2)
};

class Simulator {
 public:
  // Builds the scenario's scene, textures and renderer. Fails on bad options or when no
  // OSMesa context can be created.
  static std::unique_ptr<Simulator> Create(const SimOptions& options, Status* status);
  ~Simulator();

  const SimOptions& options() const { return options_; }
  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  // Geometry and trajectories (the texture images are released once uploaded).
  const Scene& scene() const { return scene_; }
  int num_frames() const { return options_.num_frames; }
  int64_t FrameUtime(int k) const { return options_.FrameUtime(k); }

  // Ground truth without rendering (fast).
  Rigid3d WorldFromCam(int64_t utime) const;
  // Pose of body `id` (0 = static world = identity); identity for an unknown id.
  Rigid3d WorldFromBody(int id, int64_t utime) const;
  // Moving bodies' ids in ascending order.
  std::vector<int> MovingBodyIds() const;

  // Renders frame k (0 <= k < num_frames). The frame's images are (re)allocated: buffers
  // shared with an earlier frame's cv::Mat copies are never written into.
  Status RenderFrame(int k, SimFrame* frame, const RenderRequest& request = RenderRequest());
  // Poses, velocities and body descriptions of frame k, no pixels.
  Status FrameTruth(int k, SimFrame* frame) const;

  // Ground-truth points on the surfaces of body `id`, in the body frame (m). Empty for
  // an unknown id.
  const std::vector<Eigen::Vector3d>& SurfacePoints(int id) const;

  // Robot scenarios: wheel odometry (noisy and true) and the camera extrinsic.
  bool has_odometry() const { return scene_.base.has_value(); }
  const std::vector<OdometrySample>& odometry() const { return odometry_; }
  const std::vector<OdometrySample>& odometry_truth() const { return odometry_truth_; }
  std::optional<Rigid3d> base_from_cam() const;

 private:
  Simulator() = default;
  void GenerateOdometry();
  std::vector<Rigid3d> CamFromBodies(int64_t utime) const;

  SimOptions options_;
  CameraIntrinsics intrinsics_;
  Scene scene_;
  std::unique_ptr<Renderer> renderer_;
  std::vector<std::vector<Eigen::Vector3d>> surface_points_;  // per body index
  std::vector<OdometrySample> odometry_;
  std::vector<OdometrySample> odometry_truth_;
};

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_SIMULATOR_H_
