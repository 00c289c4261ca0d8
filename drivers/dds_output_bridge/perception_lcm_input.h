#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_LCM_INPUT_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_LCM_INPUT_H_

// camera_pose_t / objects_t (decoded) -> the plain structs of ros2_perception_conversion.h,
// with the checks a ROS 2 consumer relies on. Quaternions [w, x, y, z] in lcmtypes.

#include "common/util/status.h"
#include "drivers/dds_output_bridge/ros2_perception_conversion.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/objects_t.hpp"

namespace mbslam {

// Quaternion [w, x, y, z] as the message gives it: kept bit for bit when its norm is
// within 1e-6 of 1, normalised when within 1e-2 (*renormalised = true), else an error
// (non-finite or zero quaternions included).
Status QuaternionFromWxyz(const double wxyz[4], Eigen::Quaterniond* q, bool* renormalised);

// Fails on a non-finite position, a bad quaternion or an unknown tracking / scale state.
Status FromLcm(const mbslam::camera_pose_t& msg, CameraPoseSample* pose, bool* renormalised);

// Objects with a non-finite pose, velocity or extent, a negative extent, a bad
// quaternion or an unknown state are left out and counted in *invalid_objects (the
// reason of the last one in *invalid_reason); the message itself fails only on an
// unknown scale state or a num_objects that disagrees with the array.
Status FromLcm(const mbslam::objects_t& msg, ObjectsSample* objects, int* invalid_objects,
               std::string* invalid_reason, int* renormalised);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_LCM_INPUT_H_
