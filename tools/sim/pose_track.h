#ifndef MBSLAM_TOOLS_SIM_POSE_TRACK_H_
#define MBSLAM_TOOLS_SIM_POSE_TRACK_H_

// Trajectories of the simulator: poses world_from_body as functions of time (int64 µs),
// stored as dense samples (default every 1 ms) and interpolated on SE(3). Velocities are
// central differences of the samples, so they are consistent with the poses by
// construction. Builders for planar (unicycle) paths of vehicles, people and robots.

#include <Eigen/Core>

#include <cstdint>
#include <functional>
#include <vector>

#include "services/perception/geometry/rigid3.h"

namespace mbslam {
namespace sim {

// Pose and velocity of a body at one time.
struct MotionState {
  Rigid3d world_from_body;
  Eigen::Vector3d linear_velocity =
      Eigen::Vector3d::Zero();  // of the body origin, world frame (m/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // world frame (rad/s)
};

class PoseTrack {
 public:
  PoseTrack() = default;

  // Samples `world_from_body(utime)` every `step_us` over [begin_utime, end_utime].
  static PoseTrack Sample(const std::function<Rigid3d(int64_t utime)>& world_from_body,
                          int64_t begin_utime, int64_t end_utime, int64_t step_us = 1000);
  // A body that never moves.
  static PoseTrack Constant(const Rigid3d& world_from_body);

  // Pose at `utime`: geodesic interpolation between samples; clamped to the first / last
  // sample outside the sampled interval.
  Rigid3d WorldFromBody(int64_t utime) const;
  // Pose and velocities (central differences over one sample step).
  MotionState StateAt(int64_t utime) const;

  bool empty() const { return samples_.empty(); }
  int64_t begin_utime() const { return begin_utime_; }
  int64_t end_utime() const {
    return begin_utime_ + step_us_ * static_cast<int64_t>(samples_.size() - 1);
  }

 private:
  int64_t begin_utime_ = 0;
  int64_t step_us_ = 1000;
  std::vector<Rigid3d> samples_;
};

// A planar path of a ground vehicle / person / robot (unicycle model): heading along the
// body x axis, z up. Built from segments of constant longitudinal acceleration and yaw
// rate, integrated as they are added with a 1 ms step. Times are seconds from the start
// of the path.
class PlanarPath {
 public:
  struct State {
    double x = 0.0;         // position (m)
    double y = 0.0;         // position (m)
    double yaw = 0.0;       // heading from world x towards y (rad)
    double speed = 0.0;     // along the heading (m/s)
    double yaw_rate = 0.0;  // (rad/s)
  };

  // x, y: start position (m); yaw: start heading (rad); speed: start speed (m/s).
  PlanarPath(double x, double y, double yaw, double speed);

  // Stands still for `duration_s` (speed 0).
  PlanarPath& Wait(double duration_s);
  // Drives for `duration_s` with constant longitudinal acceleration (m/s^2; the speed
  // never goes below 0) and yaw rate (rad/s; applied only while moving).
  PlanarPath& Drive(double duration_s, double acceleration = 0.0, double yaw_rate = 0.0);
  // Changes speed linearly to `speed` (m/s) over `duration_s`, optionally turning.
  PlanarPath& RampTo(double speed, double duration_s, double yaw_rate = 0.0);
  // Turns by `angle_rad` at the current speed with yaw rate of magnitude |yaw_rate|.
  PlanarPath& Turn(double angle_rad, double yaw_rate_abs);

  // State at `t_s` seconds from the start. Before the start the path is extended
  // backwards along the initial heading at the initial speed, after the end forwards with
  // the final speed and yaw rate.
  State At(double t_s) const;
  double duration_s() const;

  // world_from_body of a body riding the path with its origin at `height` (m) above the
  // ground, sampled over [begin_utime, end_utime]; path time 0 is `start_utime`.
  PoseTrack ToTrack(int64_t start_utime, int64_t begin_utime, int64_t end_utime,
                    double height) const;

 private:
  static constexpr double kStepS = 1e-3;
  void Advance(double duration_s, double acceleration, double yaw_rate, bool wait);
  std::vector<State> knots_;  // state every kStepS from t = 0
};

// Rigid3d for a heading (yaw about world z) and position.
Rigid3d PlanarPose(double x, double y, double z, double yaw);

// base_from_cam for a camera looking along the base x axis (base: x forward, y left,
// z up; camera: x right, y down, z forward), mounted at `translation` and pitched down
// by `pitch_down_rad` (positive looks down), yawed left by `yaw_left_rad`.
Rigid3d ForwardCameraMount(const Eigen::Vector3d& translation, double pitch_down_rad,
                           double yaw_left_rad = 0.0);

// Rotation of a smooth random "hand shake": a sum of sinusoids per axis with random
// frequencies in [f_min, f_max] Hz and phases from `seed`, with RMS amplitude `rms`
// (rad for rotations, m for translations).
class SmoothNoise3 {
 public:
  SmoothNoise3(uint64_t seed, double rms, double f_min_hz, double f_max_hz, int terms = 4);
  Eigen::Vector3d At(double t_s) const;

 private:
  struct Term {
    double amplitude, frequency, phase;
  };
  std::vector<Term> terms_[3];
};

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_POSE_TRACK_H_
