#ifndef MBSLAM_COMMON_LCM_ALL_TYPES_H_
#define MBSLAM_COMMON_LCM_ALL_TYPES_H_

// Every message type of the contract, for code that must handle all of them (round-trip
// tests, fuzz targets, log dumpers). A test checks this list against lcmtypes/*.lcm.

#include "mbslam/body_state_t.hpp"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/counter_t.hpp"
#include "mbslam/feature_track_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/image_hull_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/keyframe_t.hpp"
#include "mbslam/map_t.hpp"
#include "mbslam/object_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "mbslam/pose_t.hpp"
#include "mbslam/predicted_volume_t.hpp"
#include "mbslam/queue_status_t.hpp"
#include "mbslam/snapshot_request_t.hpp"
#include "mbslam/stage_timing_t.hpp"
#include "mbslam/status_t.hpp"
#include "mbslam/tracks_t.hpp"

// X(type) for every type.
#define MBSLAM_FOR_EACH_LCM_TYPE(X) \
  X(body_state_t)                   \
  X(camera_calibration_t)           \
  X(camera_pose_t)                  \
  X(counter_t)                      \
  X(feature_track_t)                \
  X(ground_truth_t)                 \
  X(image_hull_t)                   \
  X(image_t)                        \
  X(keyframe_t)                     \
  X(map_t)                          \
  X(object_t)                       \
  X(objects_t)                      \
  X(occupancy_t)                    \
  X(odometry_t)                     \
  X(pose_t)                         \
  X(predicted_volume_t)             \
  X(queue_status_t)                 \
  X(snapshot_request_t)             \
  X(stage_timing_t)                 \
  X(status_t)                       \
  X(tracks_t)

#endif  // MBSLAM_COMMON_LCM_ALL_TYPES_H_
