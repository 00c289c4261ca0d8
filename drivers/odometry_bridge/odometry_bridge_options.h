#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_BRIDGE_OPTIONS_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_BRIDGE_OPTIONS_H_

// Options of odometry_bridge (config/odometry_bridge.yaml).

#include <array>
#include <string>

#include "common/config/options.h"
#include "common/lcm/channels.h"
#include "common/util/status.h"
#include "drivers/odometry_bridge/dds_options.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

// The robot-to-camera extrinsic base_from_cam: maps points in the camera frame (x
// right, y down, z forward) into the robot base frame.
struct ExtrinsicOptions {
  std::array<double, 3> translation = {0.0, 0.0, 0.0};          // camera origin in the base frame (m)
  std::array<double, 4> rotation_wxyz = {0.5, -0.5, 0.5, -0.5};  // rotation [w, x, y, z]; default: camera looking along base +x, image right = base -y, image down = base -z
  std::string file = "";  // YAML with translation [m] and quaternion [w, x, y, z] (simulator extrinsic.yaml, handeye_calib output); overrides the two above

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("translation", &translation, "camera origin in the base frame (m)");
    v("rotation_wxyz", &rotation_wxyz, "rotation [w, x, y, z] (default: camera looking along base +x, x-forward/z-up base)");
    v("file", &file, "YAML with translation + quaternion [w,x,y,z]; overrides the two above");
  }
  // base_from_cam from the fields, or from `file` when set.
  Status Resolve(Rigid3d* base_from_cam) const;
};

// Reads {translation: [x, y, z], quaternion: [w, x, y, z]}, optionally under a
// `base_from_cam:` key.
Status LoadExtrinsicYaml(const std::string& path, Rigid3d* base_from_cam);
std::string ExtrinsicToYaml(const Rigid3d& base_from_cam, const std::string& comment);

struct ImageSyncOptions {
  bool enabled = false;                               // interpolate odometry to CAMERA_IMAGE times and publish the camera pose
  std::string output_channel = "ODOMETRY_CAMERA_POSE";  // pose_t odom_from_cam at each image time
  double max_gap_s = 0.5;                             // largest odometry gap to interpolate across (s)
  double max_wait_s = 0.5;                            // how long (message time) an image may wait for newer odometry (s)
  int max_pending_images = 100;                       // images waiting for odometry (count)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("enabled", &enabled, "interpolate odometry to CAMERA_IMAGE times, publish odom_from_cam");
    v("output_channel", &output_channel, "pose_t odom_from_cam at each image time");
    v("max_gap_s", &max_gap_s, "largest odometry gap to interpolate across (s)");
    v("max_wait_s", &max_wait_s, "how long an image may wait for newer odometry (s, message time)");
    v("max_pending_images", &max_pending_images, "images waiting for odometry (count)");
  }
};

struct OdometryBridgeOptions {
  std::string input = "dds";           // dds | csv | tum | lcm
  std::string file = "";               // csv / tum input file
  std::string pose_channel = "ROBOT_POSE";  // lcm input: pose_t channel (e.g. motion capture)
  bool derive_twist = true;            // tum / lcm inputs: twist from consecutive poses (covariance stays unknown)
  std::string lcm_url = "";            // LCM URL (empty = LCM default); images and the lcm input come from here too
  double speed = 0.0;                  // file inputs on a bus: 1 = recorded rate, N x, 0 = as fast as possible
  int64_t max_messages = 0;            // stop after this many published messages (0 = no limit)
  double idle_timeout_s = 0.0;         // live inputs: stop after this long without a message (s, 0 = never)
  DdsOptions dds;
  ExtrinsicOptions base_from_cam;
  ImageSyncOptions image_sync;
  ChannelOptions channels;

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("input", &input, "dds | csv | tum | lcm");
    v("file", &file, "csv / tum input file");
    v("pose_channel", &pose_channel, "lcm input: pose_t channel");
    v("derive_twist", &derive_twist, "tum / lcm inputs: twist from consecutive poses");
    v("lcm_url", &lcm_url, "LCM URL (empty = LCM default)");
    v("speed", &speed, "file inputs on a bus: 1 = recorded rate, N x, 0 = as fast as possible");
    v("max_messages", &max_messages, "stop after this many published messages (0 = no limit)");
    v("idle_timeout_s", &idle_timeout_s, "live inputs: stop after this long without a message (s, 0 = never)");
    v("dds", &dds, "ROS 2 over Fast DDS");
    v("base_from_cam", &base_from_cam, "robot-to-camera extrinsic");
    v("image_sync", &image_sync, "odometry interpolated to image times");
    v("channels", &channels, "LCM channel names");
  }
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_ODOMETRY_BRIDGE_OPTIONS_H_
