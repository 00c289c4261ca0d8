#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_TEST_READER_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_TEST_READER_H_

// For tests: a ROS 2 subscriber of the bridge's three topics, built from the same
// generated types (a reliable, keep-all reader per enabled topic, as `ros2 topic echo`
// would subscribe). Keeps every sample it receives.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "drivers/dds_output_bridge/perception_dds_bridge_options.h"
#include "geometry_msgs/msg/dds_/PoseArray_.h"
#include "geometry_msgs/msg/dds_/PoseStamped_.h"
#include "visualization_msgs/msg/dds_/MarkerArray_.h"

namespace mbslam {

class Ros2PerceptionTestReader {
 public:
  static std::unique_ptr<Ros2PerceptionTestReader> Create(const DdsOutputOptions& dds,
                                                          const Ros2TopicOptions& topics,
                                                          Status* status);
  ~Ros2PerceptionTestReader();
  Ros2PerceptionTestReader(const Ros2PerceptionTestReader&) = delete;
  Ros2PerceptionTestReader& operator=(const Ros2PerceptionTestReader&) = delete;

  // Waits until every enabled topic has at least `count` matched writers.
  bool WaitForWriters(int count, int64_t timeout_us) const;
  // Waits until at least this many samples arrived on each topic.
  bool WaitForSamples(size_t camera_poses, size_t objects, size_t object_poses,
                      int64_t timeout_us) const;

  std::vector<geometry_msgs::msg::dds_::PoseStamped_> camera_poses() const;
  std::vector<visualization_msgs::msg::dds_::MarkerArray_> objects() const;
  std::vector<geometry_msgs::msg::dds_::PoseArray_> object_poses() const;
  // The registered type names per topic, e.g. "geometry_msgs::msg::dds_::PoseStamped_".
  std::string type_names() const;

  struct Impl;

 private:
  explicit Ros2PerceptionTestReader(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_ROS2_PERCEPTION_TEST_READER_H_
