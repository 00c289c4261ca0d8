#ifndef MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_TEST_MESSAGES_H_
#define MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_TEST_MESSAGES_H_

// For the bridge's tests: LCM inputs with awkward values (thirds, 1e-9 steps, times
// with µs) and an exact comparison of what arrives over DDS.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "geometry_msgs/msg/dds_/Pose_.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/objects_t.hpp"

namespace mbslam {
namespace testing_util {

// Same bits (tells 0.0 from -0.0, and NaNs apart).
inline bool BitEqual(double a, double b) {
  uint64_t ia = 0, ib = 0;
  std::memcpy(&ia, &a, sizeof(double));
  std::memcpy(&ib, &b, sizeof(double));
  return ia == ib;
}

// Image i of a 30 Hz sequence: utime 1700000000.000007 s + i * 33333 µs, tracking.
inline mbslam::camera_pose_t TestCameraPose(int i) {
  mbslam::camera_pose_t m{};
  m.utime = 1700000000000000 + 33333 * int64_t{i} + 7;
  m.frame_seq = i;
  m.position[0] = 0.1 * i;
  m.position[1] = -1.0 / 3.0;
  m.position[2] = 2.0 + 1e-9 * i;
  const double angle = 0.01 * i;
  m.orientation[0] = std::cos(angle / 2);  // [w, x, y, z]: about (0.6, 0, 0.8)
  m.orientation[1] = 0.6 * std::sin(angle / 2);
  m.orientation[2] = 0.0;
  m.orientation[3] = 0.8 * std::sin(angle / 2);
  m.tracking_state = mbslam::camera_pose_t::TRACKING_OK;
  m.scale_state = mbslam::camera_pose_t::SCALE_METRIC;
  m.scale_to_metric = 1.0;
  return m;
}

// Objects 4 (tracked, moving at 2 m/s along x), 7 (reconstructed, at rest) and 9
// (detected only), at 1700000000.5 s.
inline mbslam::objects_t TestObjects() {
  mbslam::objects_t m{};
  m.utime = 1700000000500000;
  m.frame_seq = 15;
  m.scale_state = mbslam::camera_pose_t::SCALE_METRIC;
  for (int id : {4, 7}) {
    mbslam::object_t o{};
    o.id = id;
    o.state = id == 4 ? mbslam::object_t::STATE_TRACKED : mbslam::object_t::STATE_RECONSTRUCTED;
    o.position[0] = 1.5 * id;
    o.position[1] = 0.75;
    o.position[2] = 12.0 - id;
    o.orientation[0] = std::sqrt(0.5);  // [w, x, y, z]: 90 degrees about y
    o.orientation[2] = std::sqrt(0.5);
    o.linear_velocity[0] = id == 4 ? 2.0 : 0.0;
    o.extent[0] = 4.25;
    o.extent[1] = 1.5;
    o.extent[2] = 0.1 * id;
    m.objects.push_back(o);
  }
  mbslam::object_t detected{};
  detected.id = 9;
  detected.state = mbslam::object_t::STATE_DETECTED;
  detected.orientation[0] = 1.0;
  m.objects.push_back(detected);
  m.num_objects = static_cast<int32_t>(m.objects.size());
  return m;
}

// ROS pose (x, y, z, w) against the LCM arrays ([w, x, y, z]), bit for bit.
inline void ExpectPoseExact(const geometry_msgs::msg::dds_::Pose_& got, const double position[3],
                            const double orientation_wxyz[4]) {
  EXPECT_TRUE(BitEqual(got.position_().x_(), position[0]));
  EXPECT_TRUE(BitEqual(got.position_().y_(), position[1]));
  EXPECT_TRUE(BitEqual(got.position_().z_(), position[2]));
  EXPECT_TRUE(BitEqual(got.orientation_().x_(), orientation_wxyz[1]));
  EXPECT_TRUE(BitEqual(got.orientation_().y_(), orientation_wxyz[2]));
  EXPECT_TRUE(BitEqual(got.orientation_().z_(), orientation_wxyz[3]));
  EXPECT_TRUE(BitEqual(got.orientation_().w_(), orientation_wxyz[0]));
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_DDS_OUTPUT_BRIDGE_TEST_MESSAGES_H_
