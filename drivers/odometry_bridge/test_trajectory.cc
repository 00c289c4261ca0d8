#include "drivers/odometry_bridge/test_trajectory.h"

#include <cmath>

#include "common/util/time.h"

namespace mbslam {

OdometrySample FieldTestOdometry(int64_t index) {
  const double k = static_cast<double>(index);
  OdometrySample s;
  s.utime = 1700000000000000 + 20000 * index + 7;
  s.seq = index;
  s.frame_id = "odom";
  s.child_frame_id = "base_footprint";
  s.odom_from_base.translation = Eigen::Vector3d(0.1 * k + 1.0 / 3.0, -0.05 * k - 1.0 / 7.0, 0.25 + 1e-9 * k);
  s.odom_from_base.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * k + 0.1, Eigen::Vector3d(0.1, -0.2, 1.0).normalized()));
  for (size_t i = 0; i < 36; ++i) {
    s.pose_covariance[i] = static_cast<double>(i) + 0.001 * k + 1.0 / (static_cast<double>(i) + 3.0);
    s.twist_covariance[i] = -static_cast<double>(i) * 1e-3 + 1e-6 * k;
  }
  s.linear_velocity = Eigen::Vector3d(0.5 + 0.01 * k, -1.0 / 9.0, 1e-7 * k);
  s.angular_velocity = Eigen::Vector3d(1e-3, -2e-3 * k, 0.3 + 1.0 / 11.0);
  return s;
}

Rigid3d ScrewTrajectory::At(int64_t utime) const {
  return start * Rigid3d::Exp(twist * UtimeToSeconds(utime - t0_utime));
}

OdometrySample ScrewTrajectory::Sample(int64_t utime, int64_t seq) const {
  OdometrySample s;
  s.utime = utime;
  s.seq = seq;
  s.odom_from_base = At(utime);
  s.linear_velocity = twist.head<3>();
  s.angular_velocity = twist.tail<3>();
  return s;
}

}  // namespace mbslam
