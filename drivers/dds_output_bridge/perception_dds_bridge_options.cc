#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"

#include <arpa/inet.h>

#include <cctype>
#include <cmath>

namespace mbslam {
namespace {

bool IsIpv4(const std::string& text) {
  in_addr addr{};
  return inet_pton(AF_INET, text.c_str(), &addr) == 1;
}

// Splits on '/', dropping empty tokens.
std::vector<std::string> Tokens(const std::string& name) {
  std::vector<std::string> tokens;
  std::string token;
  for (char c : name) {
    if (c == '/') {
      if (!token.empty()) tokens.push_back(token);
      token.clear();
    } else {
      token += c;
    }
  }
  if (!token.empty()) tokens.push_back(token);
  return tokens;
}

}  // namespace

bool IsValidRos2Name(const std::string& name) {
  if (name.empty()) return false;
  for (size_t i = 1; i + 1 < name.size(); ++i) {
    if (name[i] == '/' && name[i + 1] == '/') return false;
  }
  const std::vector<std::string> tokens = Tokens(name);
  if (tokens.empty()) return false;
  for (const std::string& t : tokens) {
    if (std::isdigit(static_cast<unsigned char>(t[0]))) return false;
    for (char c : t) {
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
    }
  }
  return true;
}

std::string Ros2DdsTopicName(const std::string& prefix, const std::string& name) {
  if (name.empty()) return "";
  std::string topic = "rt";
  for (const std::string& t : Tokens(prefix)) topic += "/" + t;
  for (const std::string& t : Tokens(name)) topic += "/" + t;
  return topic;
}

bool DdsOutputOptions::Check() const {
  MBSLAM_CHECK_OPTION_GE(domain_id, 0);
  MBSLAM_CHECK_OPTION_LE(domain_id, 232);
  MBSLAM_CHECK_OPTION(transport == "udp" || transport == "shm");
  if (transport == "udp") {
    MBSLAM_CHECK_OPTION(!interfaces.empty());
    MBSLAM_CHECK_OPTION(!initial_peers.empty());
    for (const std::string& a : interfaces) MBSLAM_CHECK_OPTION(IsIpv4(a));
    for (const std::string& a : initial_peers) MBSLAM_CHECK_OPTION(IsIpv4(a));
  }
  MBSLAM_CHECK_OPTION_GE(max_initial_peers_range, 1);
  MBSLAM_CHECK_OPTION_LE(max_initial_peers_range, 120);
  MBSLAM_CHECK_OPTION_GT(history_depth, 0);
  return true;
}

bool Ros2TopicOptions::Check() const {
  MBSLAM_CHECK_OPTION(prefix.empty() || IsValidRos2Name(prefix));
  MBSLAM_CHECK_OPTION(camera_pose.empty() || IsValidRos2Name(camera_pose));
  MBSLAM_CHECK_OPTION(objects.empty() || IsValidRos2Name(objects));
  MBSLAM_CHECK_OPTION(object_poses.empty() || IsValidRos2Name(object_poses));
  MBSLAM_CHECK_OPTION(!camera_pose.empty() || !objects.empty() || !object_poses.empty());
  // Two outputs on one topic would be two types on one topic.
  MBSLAM_CHECK_OPTION(camera_pose.empty() ||
                      Ros2DdsTopicName(prefix, camera_pose) != Ros2DdsTopicName(prefix, objects));
  MBSLAM_CHECK_OPTION(camera_pose.empty() || Ros2DdsTopicName(prefix, camera_pose) !=
                                                 Ros2DdsTopicName(prefix, object_poses));
  MBSLAM_CHECK_OPTION(objects.empty() ||
                      Ros2DdsTopicName(prefix, objects) != Ros2DdsTopicName(prefix, object_poses));
  return true;
}

bool Ros2MarkerOptions::Check() const {
  MBSLAM_CHECK_OPTION(std::isfinite(min_scale));
  MBSLAM_CHECK_OPTION_GT(min_scale, 0.0);
  MBSLAM_CHECK_OPTION_GE(alpha, 0.0);
  MBSLAM_CHECK_OPTION_LE(alpha, 1.0);
  MBSLAM_CHECK_OPTION_GT(arrow_horizon_s, 0.0);
  MBSLAM_CHECK_OPTION_GT(arrow_shaft_diameter, 0.0);
  MBSLAM_CHECK_OPTION_GT(arrow_head_diameter, 0.0);
  MBSLAM_CHECK_OPTION_GT(label_height, 0.0);
  MBSLAM_CHECK_OPTION_GE(lifetime_s, 0.0);
  MBSLAM_CHECK_OPTION_LT(lifetime_s, 2.0e9);  // fits builtin_interfaces/Duration
  return true;
}

bool PerceptionDdsBridgeOptions::Check() const {
  MBSLAM_CHECK_OPTION_GT(queue_capacity, 0);
  MBSLAM_CHECK_OPTION_GT(max_message_mb, 0.0);
  MBSLAM_CHECK_OPTION_LE(max_message_mb, 4096.0);
  MBSLAM_CHECK_OPTION(!frame_id.empty());
  MBSLAM_CHECK_OPTION_GE(wait_for_subscribers, 0);
  MBSLAM_CHECK_OPTION_GT(wait_timeout_s, 0.0);
  MBSLAM_CHECK_OPTION_GE(linger_s, 0.0);
  MBSLAM_CHECK_OPTION_SECTION(dds);
  MBSLAM_CHECK_OPTION_SECTION(topics);
  MBSLAM_CHECK_OPTION_SECTION(markers);
  MBSLAM_CHECK_OPTION_SECTION(channels);
  return true;
}

}  // namespace mbslam
