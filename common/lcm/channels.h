#ifndef MBSLAM_COMMON_LCM_CHANNELS_H_
#define MBSLAM_COMMON_LCM_CHANNELS_H_

// Every LCM channel name of the system, defined once. Each process loads this struct
// from the `channels:` section of its config, so any name can be overridden.

#include <string>

#include "common/config/options.h"

namespace mbslam {

struct ChannelOptions {
  std::string camera_image = "CAMERA_IMAGE";               // image_t
  std::string camera_calibration = "CAMERA_CALIBRATION";   // camera_calibration_t
  std::string odometry = "ODOMETRY";                       // odometry_t
  std::string ground_truth = "GROUND_TRUTH";               // ground_truth_t (simulator / datasets)
  std::string perception_camera_pose = "PERCEPTION_CAMERA_POSE";  // camera_pose_t
  std::string perception_objects = "PERCEPTION_OBJECTS";   // objects_t
  std::string perception_map = "PERCEPTION_MAP";           // map_t
  std::string perception_occupancy = "PERCEPTION_OCCUPANCY";  // occupancy_t
  std::string perception_tracks = "PERCEPTION_TRACKS";     // tracks_t
  std::string perception_status = "PERCEPTION_STATUS";     // status_t
  std::string snapshot_request = "SNAPSHOT_REQUEST";       // snapshot_request_t

  bool Check() const;

  template <typename Visitor>
  void VisitFields(Visitor& v) {
    v("camera_image", &camera_image, "image_t from camera_driver");
    v("camera_calibration", &camera_calibration, "camera_calibration_t from camera_driver");
    v("odometry", &odometry, "odometry_t from odometry_bridge");
    v("ground_truth", &ground_truth, "ground_truth_t from the simulator / dataset converters");
    v("perception_camera_pose", &perception_camera_pose, "camera_pose_t");
    v("perception_objects", &perception_objects, "objects_t");
    v("perception_map", &perception_map, "map_t");
    v("perception_occupancy", &perception_occupancy, "occupancy_t");
    v("perception_tracks", &perception_tracks, "tracks_t (debug)");
    v("perception_status", &perception_status, "status_t");
    v("snapshot_request", &snapshot_request, "snapshot_request_t");
  }
};

// True for names LCM can carry and that are not regular expressions: [A-Za-z0-9_/-]+ (no regex characters).
bool IsValidChannelName(const std::string& name);

}  // namespace mbslam

#endif  // MBSLAM_COMMON_LCM_CHANNELS_H_
