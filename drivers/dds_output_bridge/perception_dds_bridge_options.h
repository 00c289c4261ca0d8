#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_DDS_BRIDGE_OPTIONS_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_DDS_BRIDGE_OPTIONS_H_

// Options of perception_dds_bridge (config/perception_dds_bridge.yaml).

#include <string>
#include <vector>

#include "common/config/options.h"
#include "common/lcm/channels.h"

namespace mbslam {

// How the bridge joins DDS. Never Fast DDS's default (multicast discovery on every
// interface): UDPv4 on the listed interfaces with unicast discovery through the listed
// peers (loopback by default), or shared memory only.
struct DdsOutputOptions {
  int domain_id = 0;  // DDS domain (ROS_DOMAIN_ID), 0-232
  std::string transport =
      "udp";  // udp (listed interfaces, unicast peers) | shm (shared memory only)
  std::vector<std::string> interfaces = {"127.0.0.1"};     // udp: IPv4 interface whitelist
  std::vector<std::string> initial_peers = {"127.0.0.1"};  // udp: unicast discovery peers (IPv4)
  int max_initial_peers_range = 32;  // udp: participant ids announced to on each peer (count)
  bool reliable = true;              // writers: reliable (matches reliable and best-effort readers)
  bool transient_local = false;  // writers: keep the last history_depth samples for late-joining
                                 // transient-local readers
  int history_depth = 10;        // samples kept per writer (count)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("domain_id", &domain_id, "DDS domain (ROS_DOMAIN_ID), 0-232");
    v("transport", &transport,
      "udp (listed interfaces + unicast peers, no multicast) | shm (shared memory only)");
    v("interfaces", &interfaces, "udp: IPv4 interface whitelist");
    v("initial_peers", &initial_peers, "udp: unicast discovery peers (IPv4)");
    v("max_initial_peers_range", &max_initial_peers_range,
      "udp: participant ids announced to on each peer (count)");
    v("reliable", &reliable, "reliable writers (match reliable and best-effort readers)");
    v("transient_local", &transient_local,
      "writers keep the last history_depth samples for late-joining transient-local readers");
    v("history_depth", &history_depth, "samples kept per writer (count)");
  }
};

// ROS 2 topic names. Each DDS topic is rt/<prefix>/<name>; an empty name switches that
// output off.
struct Ros2TopicOptions {
  std::string prefix = "mbslam";              // namespace of the topics ("" = none)
  std::string camera_pose = "camera_pose";    // geometry_msgs/msg/PoseStamped
  std::string objects = "objects";            // visualization_msgs/msg/MarkerArray
  std::string object_poses = "object_poses";  // geometry_msgs/msg/PoseArray

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("prefix", &prefix, "namespace of the topics (\"\" = none)");
    v("camera_pose", &camera_pose, "geometry_msgs/msg/PoseStamped (\"\" = off)");
    v("objects", &objects, "visualization_msgs/msg/MarkerArray (\"\" = off)");
    v("object_poses", &object_poses, "geometry_msgs/msg/PoseArray (\"\" = off)");
  }
};

// How objects become markers: one CUBE per object (its pose and extent), optionally a
// velocity ARROW and a TEXT label. Lengths are in world units (metres once the world
// frame is metric).
struct Ros2MarkerOptions {
  bool include_detected =
      false;  // also objects in STATE_DETECTED (no reliable estimate yet), in markers and poses
  double min_scale = 0.01;       // smallest box side, so rviz draws zero extents (world units)
  double alpha = 0.5;            // box opacity, 0-1
  bool velocity_arrows = true;   // ARROW from the object along its velocity
  double arrow_horizon_s = 1.0;  // arrow length = speed * this (s)
  double arrow_shaft_diameter = 0.05;  // (world units)
  double arrow_head_diameter = 0.1;    // (world units)
  bool labels = true;                  // TEXT_VIEW_FACING "#id speed" at the object
  double label_height = 0.25;          // text height (world units)
  double lifetime_s = 0.0;             // marker lifetime (s, 0 = until replaced)
  bool delete_all_first = true;  // each array starts with DELETEALL, so vanished objects disappear

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("include_detected", &include_detected,
      "also objects in STATE_DETECTED (no reliable estimate yet), in markers and poses");
    v("min_scale", &min_scale, "smallest box side (world units)");
    v("alpha", &alpha, "box opacity, 0-1");
    v("velocity_arrows", &velocity_arrows, "ARROW from the object along its velocity");
    v("arrow_horizon_s", &arrow_horizon_s, "arrow length = speed * this (s)");
    v("arrow_shaft_diameter", &arrow_shaft_diameter, "(world units)");
    v("arrow_head_diameter", &arrow_head_diameter, "(world units)");
    v("labels", &labels, "TEXT_VIEW_FACING \"#id speed\" at the object");
    v("label_height", &label_height, "text height (world units)");
    v("lifetime_s", &lifetime_s, "marker lifetime (s, 0 = until replaced)");
    v("delete_all_first", &delete_all_first,
      "each array starts with DELETEALL (vanished objects disappear)");
  }
};

struct PerceptionDdsBridgeOptions {
  std::string lcm_url = "";      // LCM URL ("" = LCM default; file://LOG?speed=0 replays a log)
  int queue_capacity = 100;      // messages LCM buffers per subscription (count)
  double max_message_mb = 64.0;  // larger messages are rejected before decoding (MiB)
  std::string frame_id = "map";  // header.frame_id: the ROS name of mbslam's world frame
  bool publish_untracked_poses =
      false;  // also camera poses while not tracking (NOT_INITIALIZED, INITIALIZING, LOST)
  int wait_for_subscribers =
      0;  // before reading LCM, wait until every output has this many readers (count)
  double wait_timeout_s = 30.0;    // how long to wait for them (s)
  bool exit_at_end_of_log = true;  // with a file:// URL, stop at the end of the log
  double linger_s = 2.0;  // at exit, wait this long for reliable readers to acknowledge (s)
  DdsOutputOptions dds;
  Ros2TopicOptions topics;
  Ros2MarkerOptions markers;
  ChannelOptions channels;

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("lcm_url", &lcm_url, "LCM URL (\"\" = LCM default; file://LOG?speed=0 replays a log)");
    v("queue_capacity", &queue_capacity, "messages LCM buffers per subscription (count)");
    v("max_message_mb", &max_message_mb, "larger messages are rejected before decoding (MiB)");
    v("frame_id", &frame_id, "header.frame_id: the ROS name of mbslam's world frame");
    v("publish_untracked_poses", &publish_untracked_poses,
      "also camera poses while not tracking (NOT_INITIALIZED, INITIALIZING, LOST)");
    v("wait_for_subscribers", &wait_for_subscribers,
      "before reading LCM, wait until every output has this many readers (count)");
    v("wait_timeout_s", &wait_timeout_s, "how long to wait for them (s)");
    v("exit_at_end_of_log", &exit_at_end_of_log, "with a file:// URL, stop at the end of the log");
    v("linger_s", &linger_s, "at exit, wait this long for reliable readers to acknowledge (s)");
    v("dds", &dds, "ROS 2 over Fast DDS");
    v("topics", &topics, "ROS 2 topics (DDS topic rt/<prefix>/<name>)");
    v("markers", &markers, "objects as visualization_msgs/MarkerArray");
    v("channels", &channels, "LCM channel names");
  }
};

// True for a ROS 2 name made of tokens [A-Za-z_][A-Za-z0-9_]* separated by single '/'
// (a leading or trailing '/' is allowed).
bool IsValidRos2Name(const std::string& name);

// "rt/<prefix>/<name>" with redundant slashes removed; "" when `name` is empty.
std::string Ros2DdsTopicName(const std::string& prefix, const std::string& name);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_PERCEPTION_DDS_BRIDGE_OPTIONS_H_
