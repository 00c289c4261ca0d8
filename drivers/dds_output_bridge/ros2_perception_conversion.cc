#include "drivers/dds_output_bridge/ros2_perception_conversion.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "common/util/time.h"

namespace mbslam {

namespace gm = geometry_msgs::msg::dds_;
namespace vm = visualization_msgs::msg::dds_;

namespace {

bool SetStamp(int64_t utime, const std::string& frame_id, std_msgs::msg::dds_::Header_* header) {
  int32_t sec = 0;
  uint32_t nanosec = 0;
  if (!UtimeToRos2Time(utime, &sec, &nanosec)) return false;
  header->stamp_().sec_(sec);
  header->stamp_().nanosec_(nanosec);
  header->frame_id_(frame_id);
  return true;
}

Status StampError(int64_t utime) {
  return Status::Error("utime " + std::to_string(utime) +
                       " is outside ROS 2 time (int32 seconds since the epoch)");
}

gm::Point_ ToRos2Point(const Eigen::Vector3d& p) {
  gm::Point_ point;
  point.x_(p.x());
  point.y_(p.y());
  point.z_(p.z());
  return point;
}

// A marker with the fields every kind shares.
vm::Marker_ BaseMarker(const std_msgs::msg::dds_::Header_& header, const char* ns, int id,
                       int32_t type, int32_t lifetime_sec, uint32_t lifetime_nanosec) {
  vm::Marker_ m;
  m.header_(header);
  m.ns_(ns);
  m.id_(id);
  m.type_(type);
  m.action_(vm::Marker_Constants::ADD);
  m.pose_().orientation_().w_(1.0);
  m.lifetime_().sec_(lifetime_sec);
  m.lifetime_().nanosec_(lifetime_nanosec);
  m.frame_locked_(false);
  return m;
}

void SetColor(const std::array<float, 3>& rgb, float alpha, vm::Marker_* m) {
  m->color_().r_(rgb[0]);
  m->color_().g_(rgb[1]);
  m->color_().b_(rgb[2]);
  m->color_().a_(alpha);
}

}  // namespace

bool UtimeToRos2Time(int64_t utime, int32_t* sec, uint32_t* nanosec) {
  int64_t s = utime / kUsecPerSec;
  int64_t us = utime % kUsecPerSec;
  if (us < 0) {
    us += kUsecPerSec;
    --s;
  }
  if (s < std::numeric_limits<int32_t>::min() || s > std::numeric_limits<int32_t>::max())
    return false;
  *sec = static_cast<int32_t>(s);
  *nanosec = static_cast<uint32_t>(us * 1000);
  return true;
}

bool SecondsToRos2Duration(double seconds, int32_t* sec, uint32_t* nanosec) {
  if (!std::isfinite(seconds) || seconds < 0.0 || seconds >= 2147483647.0) return false;
  double whole = std::floor(seconds);
  int64_t ns = std::llround((seconds - whole) * 1e9);
  if (ns >= 1000000000) {
    ns -= 1000000000;
    whole += 1.0;
  }
  if (whole > 2147483647.0) return false;
  *sec = static_cast<int32_t>(whole);
  *nanosec = static_cast<uint32_t>(ns);
  return true;
}

void ToRos2Pose(const Rigid3d& pose, gm::Pose_* msg) {
  msg->position_(ToRos2Point(pose.translation));
  msg->orientation_().x_(pose.rotation.x());
  msg->orientation_().y_(pose.rotation.y());
  msg->orientation_().z_(pose.rotation.z());
  msg->orientation_().w_(pose.rotation.w());
}

std::array<float, 3> ObjectColor(int id) {
  static constexpr std::array<std::array<float, 3>, 8> kPalette = {{
      {0.90f, 0.10f, 0.10f},  // red
      {0.10f, 0.55f, 0.95f},  // blue
      {0.20f, 0.80f, 0.20f},  // green
      {0.95f, 0.60f, 0.05f},  // orange
      {0.60f, 0.30f, 0.85f},  // purple
      {0.00f, 0.75f, 0.75f},  // cyan
      {0.90f, 0.30f, 0.65f},  // pink
      {0.70f, 0.70f, 0.10f},  // olive
  }};
  const int n = static_cast<int>(kPalette.size());
  const int index = ((id - 1) % n + n) % n;
  return kPalette[static_cast<size_t>(index)];
}

Status ToRos2PoseStamped(const CameraPoseSample& pose, const std::string& frame_id,
                         gm::PoseStamped_* msg) {
  if (!SetStamp(pose.utime, frame_id, &msg->header_())) return StampError(pose.utime);
  ToRos2Pose(pose.world_from_cam, &msg->pose_());
  return Status::Ok();
}

bool IsPublishedObject(const ObjectSample& object, const Ros2MarkerOptions& options) {
  return options.include_detected || object.state != ObjectState::kDetected;
}

Status ToRos2MarkerArray(const ObjectsSample& objects, const std::string& frame_id,
                         const Ros2MarkerOptions& options, vm::MarkerArray_* msg) {
  std_msgs::msg::dds_::Header_ header;
  if (!SetStamp(objects.utime, frame_id, &header)) return StampError(objects.utime);
  int32_t life_sec = 0;
  uint32_t life_nanosec = 0;
  if (!SecondsToRos2Duration(options.lifetime_s, &life_sec, &life_nanosec)) {
    return Status::Error("markers.lifetime_s is not a ROS 2 duration");
  }
  std::vector<vm::Marker_>& markers = msg->markers_();
  markers.clear();
  if (options.delete_all_first) {
    vm::Marker_ m = BaseMarker(header, "", 0, vm::Marker_Constants::CUBE, 0, 0);
    m.action_(vm::Marker_Constants::DELETEALL);
    markers.push_back(std::move(m));
  }
  const char* speed_unit = objects.scale_state == ScaleState::kMetric ? "m/s" : "units/s";
  for (const ObjectSample& o : objects.objects) {
    if (!IsPublishedObject(o, options)) continue;
    const std::array<float, 3> rgb = ObjectColor(o.id);

    vm::Marker_ box = BaseMarker(header, kObjectBoxNamespace, o.id, vm::Marker_Constants::CUBE,
                                 life_sec, life_nanosec);
    ToRos2Pose(o.world_from_object, &box.pose_());
    box.scale_().x_(std::max(o.extent.x(), options.min_scale));
    box.scale_().y_(std::max(o.extent.y(), options.min_scale));
    box.scale_().z_(std::max(o.extent.z(), options.min_scale));
    SetColor(rgb, static_cast<float>(options.alpha), &box);
    markers.push_back(std::move(box));

    const double speed = o.linear_velocity.norm();
    if (options.velocity_arrows && speed > 0.0) {
      vm::Marker_ arrow = BaseMarker(header, kObjectVelocityNamespace, o.id,
                                     vm::Marker_Constants::ARROW, life_sec, life_nanosec);
      const Eigen::Vector3d& p = o.world_from_object.translation;
      arrow.points_().push_back(ToRos2Point(p));
      arrow.points_().push_back(ToRos2Point(p + o.linear_velocity * options.arrow_horizon_s));
      arrow.scale_().x_(options.arrow_shaft_diameter);
      arrow.scale_().y_(options.arrow_head_diameter);
      arrow.scale_().z_(0.0);  // head length: rviz's default
      SetColor(rgb, 1.0f, &arrow);
      markers.push_back(std::move(arrow));
    }
    if (options.labels) {
      vm::Marker_ label =
          BaseMarker(header, kObjectLabelNamespace, o.id, vm::Marker_Constants::TEXT_VIEW_FACING,
                     life_sec, life_nanosec);
      label.pose_().position_(ToRos2Point(o.world_from_object.translation));
      label.scale_().z_(options.label_height);
      SetColor(rgb, 1.0f, &label);
      char text[64];
      std::snprintf(text, sizeof(text), "#%d %.2f %s", o.id, speed, speed_unit);
      label.text_(text);
      markers.push_back(std::move(label));
    }
  }
  return Status::Ok();
}

Status ToRos2PoseArray(const ObjectsSample& objects, const std::string& frame_id,
                       const Ros2MarkerOptions& options, gm::PoseArray_* msg) {
  if (!SetStamp(objects.utime, frame_id, &msg->header_())) return StampError(objects.utime);
  msg->poses_().clear();
  for (const ObjectSample& o : objects.objects) {
    if (!IsPublishedObject(o, options)) continue;
    gm::Pose_ pose;
    ToRos2Pose(o.world_from_object, &pose);
    msg->poses_().push_back(pose);
  }
  return Status::Ok();
}

}  // namespace mbslam
