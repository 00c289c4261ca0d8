#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_SAMPLE_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_SAMPLE_H_

// One odometry measurement as the bridge handles it, between its inputs (ROS 2 over
// Fast DDS, CSV / TUM files, LCM pose_t) and odometry_t.

#include <array>
#include <cstdint>
#include <string>

#include "common/util/status.h"
#include "mbslam/odometry_t.hpp"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct OdometrySample {
  int64_t utime = 0;                     // measurement time (µs)
  int64_t seq = 0;                       // +1 per message of the source
  std::string frame_id = "odom";         // odometry frame
  std::string child_frame_id = "base_link";  // robot base frame
  Rigid3d odom_from_base;                // pose of the base in the odometry frame
  std::array<double, 36> pose_covariance = UnknownCovariance();   // row-major, ROS order; [0] = -1: unknown
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // in the base frame (m/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // in the base frame (rad/s)
  std::array<double, 36> twist_covariance = UnknownCovariance();  // row-major; [0] = -1: unknown

  static std::array<double, 36> UnknownCovariance() {
    std::array<double, 36> c{};
    c[0] = -1.0;
    return c;
  }
};

// Rejects non-finite numbers, a zero quaternion and covariances with NaN.
Status ValidateOdometrySample(const OdometrySample& sample);

// Quaternion (x, y, z, w) as a source gives it: kept bit-exact when its norm is within
// 1e-6 of 1, normalised when within 1e-2 (*renormalised = true), else an error
// (a zero quaternion, as some drivers send for "unknown", included).
Status OdometryQuaternion(double x, double y, double z, double w, Eigen::Quaterniond* q,
                          bool* renormalised);

// A pose_t message (odometry_bridge --input lcm: motion capture and the like) as a
// sample; with derive_twist and a previous sample, the twist from the two poses. Errors:
// a message that does not decode (bounds-checked), an orientation that is not a
// rotation. Callers still run ValidateOdometrySample (positions may be infinite).
Status OdometryFromPoseMessage(const uint8_t* data, size_t size, const OdometrySample* previous,
                               bool derive_twist, OdometrySample* sample);

void ToOdometryMessage(const OdometrySample& sample, mbslam::odometry_t* msg);
Status FromOdometryMessage(const mbslam::odometry_t& msg, OdometrySample* sample);

// Twist of the base from two poses dt apart: the constant body-frame twist that moves
// `previous` onto `current` (backward difference, in the frame of `current`'s base).
void TwistFromPoses(const Rigid3d& previous, const Rigid3d& current, double dt_s,
                    Eigen::Vector3d* linear_velocity, Eigen::Vector3d* angular_velocity);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_SAMPLE_H_
