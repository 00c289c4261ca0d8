#ifndef MBSLAM_DRIVERS_ODOMETRY_BRIDGE_DDS_OPTIONS_H_
#define MBSLAM_DRIVERS_ODOMETRY_BRIDGE_DDS_OPTIONS_H_

// How the bridge joins DDS. Never Fast DDS's default (multicast discovery on every
// interface): shared memory only, or UDPv4 restricted to listed interfaces with
// unicast discovery through listed peers (loopback by default).

#include <string>
#include <vector>

#include "common/config/options.h"

namespace mbslam {

struct DdsOptions {
  int domain_id = 0;                                    // DDS domain (ROS_DOMAIN_ID), 0-232
  std::string topic = "odom";                           // ROS 2 topic; DDS topic is rt/<topic>
  std::string transport = "shm";                        // shm (same host, shared memory) | udp (listed interfaces + unicast peers)
  std::vector<std::string> interfaces = {"127.0.0.1"};  // udp: IPv4 interface whitelist
  std::vector<std::string> initial_peers = {"127.0.0.1"};  // udp: unicast discovery peers
  bool reliable = false;                                // reader reliability: false matches best-effort and reliable writers
  int history_depth = 100;                              // samples kept per reader / writer (count)

  bool Check() const;
  template <typename V>
  void VisitFields(V& v) {
    v("domain_id", &domain_id, "DDS domain (ROS_DOMAIN_ID), 0-232");
    v("topic", &topic, "ROS 2 topic; the DDS topic is rt/<topic>");
    v("transport", &transport, "shm | udp (listed interfaces + unicast peers, no multicast)");
    v("interfaces", &interfaces, "udp: IPv4 interface whitelist");
    v("initial_peers", &initial_peers, "udp: unicast discovery peers");
    v("reliable", &reliable, "reliable reader (false also matches best-effort writers)");
    v("history_depth", &history_depth, "samples kept per reader / writer (count)");
  }
};

// "odom", "/odom" -> "rt/odom"; "rt/odom" stays.
std::string Ros2TopicToDds(const std::string& topic);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_ODOMETRY_BRIDGE_DDS_OPTIONS_H_
