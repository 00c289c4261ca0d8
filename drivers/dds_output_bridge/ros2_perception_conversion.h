#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_CONVERSION_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_CONVERSION_H_

// The perception outputs as plain structs, and their ROS 2 messages (the fastddsgen
// types of idl/). No LCM here: perception_lcm_input.h fills the structs.
//
// Field by field, no unit or frame change: poses stay in mbslam's world frame (named
// `frame_id` in the headers), in metres once the world is metric, map units before.
// Quaternions: Eigen inside, [w, x, y, z] in lcmtypes, (x, y, z, w) fields in ROS;
// the values are copied bit for bit.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"
#include "geometry_msgs/msg/dds_/PoseArray_.h"
#include "geometry_msgs/msg/dds_/PoseStamped_.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/pipeline/outputs.h"  // TrackingState, ScaleState, ObjectState (enums only)
#include "visualization_msgs/msg/dds_/MarkerArray_.h"

namespace mbslam {

// One PERCEPTION_CAMERA_POSE message, as far as ROS 2 gets it.
struct CameraPoseSample {
  int64_t utime = 0;       // time of the image (µs since the epoch)
  Rigid3d world_from_cam;  // camera pose in the world frame (m or map units); camera x right, y
                           // down, z forward
  TrackingState tracking_state = TrackingState::kNotInitialized;
  ScaleState scale_state = ScaleState::kUpToScale;
};

// One object of PERCEPTION_OBJECTS.
struct ObjectSample {
  int id = 0;  // > 0, unique for the run
  ObjectState state = ObjectState::kDetected;
  Rigid3d world_from_object;  // object box pose in the world (units)
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();  // in the world frame (units/s)
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();  // full box size along object x, y, z (units)
};

struct ObjectsSample {
  int64_t utime = 0;  // time of the image (µs since the epoch)
  ScaleState scale_state = ScaleState::kUpToScale;
  std::vector<ObjectSample> objects;
};

// Marker namespaces (ns) of the three marker kinds; the object id is the marker id.
inline constexpr char kObjectBoxNamespace[] = "mbslam_objects";
inline constexpr char kObjectVelocityNamespace[] = "mbslam_velocities";
inline constexpr char kObjectLabelNamespace[] = "mbslam_labels";

// µs since the epoch -> builtin_interfaces/Time, exactly: sec = floor(utime / 1e6),
// nanosec = 1000 * (utime - 1e6 * sec), in [0, 1e9). False when sec does not fit
// ROS 2's int32 (before 1901 or after 2038-01-19).
bool UtimeToRos2Time(int64_t utime, int32_t* sec, uint32_t* nanosec);

// Seconds -> builtin_interfaces/Duration (nanosec rounded to the nearest ns); false for
// negative, non-finite or too long durations.
bool SecondsToRos2Duration(double seconds, int32_t* sec, uint32_t* nanosec);

// Translation and rotation, quaternion [w, x, y, z] -> (x, y, z, w), bit for bit.
void ToRos2Pose(const Rigid3d& pose, geometry_msgs::msg::dds_::Pose_* msg);

// The colour of an object's markers (by id; alpha not set).
std::array<float, 3> ObjectColor(int id);

// Fails (and leaves *msg unusable) when the time is outside ROS 2's range.
Status ToRos2PoseStamped(const CameraPoseSample& pose, const std::string& frame_id,
                         geometry_msgs::msg::dds_::PoseStamped_* msg);

// True for objects the options publish (the DETECTED ones only with include_detected).
bool IsPublishedObject(const ObjectSample& object, const Ros2MarkerOptions& options);

// [DELETEALL,] then per published object a CUBE (ns kObjectBoxNamespace, id = object id,
// its pose, scale = extent floored at min_scale), an ARROW (kObjectVelocityNamespace,
// points object position -> position + velocity * arrow_horizon_s; none when the speed
// is 0) and a TEXT_VIEW_FACING label (kObjectLabelNamespace), as the options select.
Status ToRos2MarkerArray(const ObjectsSample& objects, const std::string& frame_id,
                         const Ros2MarkerOptions& options,
                         visualization_msgs::msg::dds_::MarkerArray_* msg);

// The poses of the published objects, in message order.
Status ToRos2PoseArray(const ObjectsSample& objects, const std::string& frame_id,
                       const Ros2MarkerOptions& options, geometry_msgs::msg::dds_::PoseArray_* msg);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_CONVERSION_H_
