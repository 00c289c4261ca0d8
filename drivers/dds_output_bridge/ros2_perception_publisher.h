#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_PUBLISHER_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_PUBLISHER_H_

// Fast DDS writers of the perception outputs as ROS 2 puts them on the wire: topics
// rt/<prefix>/<name>, types geometry_msgs::msg::dds_::PoseStamped_,
// visualization_msgs::msg::dds_::MarkerArray_ and geometry_msgs::msg::dds_::PoseArray_,
// classic CDR (generated from idl/ at build time with fastddsgen). No LCM here.

#include <cstdint>
#include <memory>
#include <string>

#include "common/util/status.h"
#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"
#include "geometry_msgs/msg/dds_/PoseArray_.h"
#include "geometry_msgs/msg/dds_/PoseStamped_.h"
#include "visualization_msgs/msg/dds_/MarkerArray_.h"

namespace mbslam {

class Ros2PerceptionPublisher {
 public:
  // One participant, a writer per enabled topic (an empty topic name disables it).
  static std::unique_ptr<Ros2PerceptionPublisher> Create(const DdsOutputOptions& dds,
                                                         const Ros2TopicOptions& topics,
                                                         Status* status);
  ~Ros2PerceptionPublisher();
  Ros2PerceptionPublisher(const Ros2PerceptionPublisher&) = delete;
  Ros2PerceptionPublisher& operator=(const Ros2PerceptionPublisher&) = delete;

  bool publishes_camera_pose() const;
  bool publishes_objects() const;
  bool publishes_object_poses() const;

  // Fails when the topic is disabled or Fast DDS refuses the sample.
  Status Publish(const geometry_msgs::msg::dds_::PoseStamped_& camera_pose);
  Status Publish(const visualization_msgs::msg::dds_::MarkerArray_& objects);
  Status Publish(const geometry_msgs::msg::dds_::PoseArray_& object_poses);

  // The smallest number of matched readers over the enabled topics.
  int min_matched_readers() const;
  // Waits until every enabled topic has at least `count` matched readers.
  bool WaitForReaders(int count, int64_t timeout_us) const;
  // Waits until reliable readers acknowledged everything written; false on timeout.
  bool WaitForAcknowledgments(int64_t timeout_us);

  // "rt/mbslam/camera_pose (geometry_msgs::msg::dds_::PoseStamped_), ... domain 0, udp".
  std::string description() const;

  struct Impl;

 private:
  explicit Ros2PerceptionPublisher(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_PUBLISHER_H_
