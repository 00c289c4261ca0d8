#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_TEST_TRAJECTORY_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_TEST_TRAJECTORY_H_

// Deterministic odometry for the test publisher and the tests that check it:
// values that are not round in binary, so any conversion loss shows up.

#include <cstdint>

#include "drivers/odometry_bridge/odometry_sample.h"

namespace mbslam {

// Sample `index` of the "fields" pattern: every field of nav_msgs/Odometry set to a
// distinct value derived from the index (stamps at 50 Hz from 1700000000 s).
OdometrySample FieldTestOdometry(int64_t index);

// A screw motion with constant body twist: odom_from_base(t) = start * Exp((t - t0) xi).
// Geodesic interpolation reproduces it exactly, so interpolation error is measurable.
struct ScrewTrajectory {
  Vector6d twist = (Vector6d() << 0.8, 0.1, 0.05, 0.02, -0.03, 0.4).finished();  // [v; w] per second
  Rigid3d start = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 0.1, 1.0).normalized())),
                          Eigen::Vector3d(1.0, -2.0, 0.1));
  int64_t t0_utime = 1700000000000000;  // µs

  Rigid3d At(int64_t utime) const;
  // Sample at a time: pose, body twist, frames; covariance unknown.
  OdometrySample Sample(int64_t utime, int64_t seq) const;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_TEST_TRAJECTORY_H_
