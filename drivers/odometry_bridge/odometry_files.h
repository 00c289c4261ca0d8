#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_FILES_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_FILES_H_

// Odometry from files.
//
// TUM: "t x y z qx qy qz qw" (t in s), pose only; twists are derived from consecutive
//      poses when asked (covariances stay unknown).
// CSV, two forms:
//  * with a header line naming the columns. Time: `utime` (µs), or `t` / `time` /
//    `timestamp` / `stamp` (s), or `sec` + `nanosec`. Pose: `x y z qx qy qz qw`.
//    Optional: `vx vy vz wx wy wz` (base frame), `frame_id`, `child_frame_id`, `seq`,
//    `pose_cov_0..35`, `twist_cov_0..35`. ROS-style long names are accepted too
//    (`header.stamp.sec`, `pose.pose.position.x`, `twist.twist.angular.z`, ...).
//  * without a header, the 89 columns of `ros2 topic echo --csv` for
//    nav_msgs/msg/Odometry: sec, nanosec, frame_id, child_frame_id, position (3),
//    orientation x y z w, pose covariance (36), linear (3), angular (3), twist
//    covariance (36).

#include <string>
#include <vector>

#include "common/util/status.h"
#include "drivers/odometry_bridge/odometry_sample.h"

namespace mbslam {

Status ReadOdometryCsv(const std::string& path, std::vector<OdometrySample>* samples);
Status ReadOdometryTum(const std::string& path, bool derive_twist,
                       std::vector<OdometrySample>* samples);

// Fills twists of pose-only samples from consecutive poses (the first sample gets the
// twist of the second).
void DeriveTwists(std::vector<OdometrySample>* samples);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_FILES_H_
