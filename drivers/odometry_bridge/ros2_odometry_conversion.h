#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ROS2_ODOMETRY_CONVERSION_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ROS2_ODOMETRY_CONVERSION_H_

// nav_msgs::msg::dds_::Odometry_ (generated from idl/ at build time) <-> OdometrySample.
// Field by field, no unit or frame change: ROS gives the pose in header.frame_id and
// the twist in child_frame_id, as odometry_t does; quaternions x y z w -> w x y z.

#include "common/util/status.h"
#include "drivers/odometry_bridge/odometry_sample.h"
#include "nav_msgs/msg/dds_/Odometry_.h"

namespace mbslam {

// Fails on non-finite values or a quaternion that is not close to unit norm.
// `*renormalised` tells that the quaternion was normalised.
Status FromRos2Odometry(const nav_msgs::msg::dds_::Odometry_& msg, OdometrySample* sample,
                        bool* renormalised);
void ToRos2Odometry(const OdometrySample& sample, nav_msgs::msg::dds_::Odometry_* msg);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ROS2_ODOMETRY_CONVERSION_H_
