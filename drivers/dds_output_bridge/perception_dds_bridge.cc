#include "drivers/dds_output_bridge/perception_dds_bridge.h"

#include <chrono>
#include <sstream>
#include <thread>

#include "common/lcm/wire_check.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "drivers/dds_output_bridge/perception_lcm_input.h"
#include "drivers/dds_output_bridge/ros2_perception_conversion.h"

namespace mbslam {

PerceptionDdsBridge::PerceptionDdsBridge(const PerceptionDdsBridgeOptions& options, LcmBus* bus,
                                         Ros2PerceptionPublisher* publisher)
    : options_(options),
      bus_(bus),
      publisher_(publisher),
      max_message_bytes_(static_cast<size_t>(options.max_message_mb * 1024.0 * 1024.0)) {
  if (publisher_->publishes_camera_pose()) {
    bus_->Subscribe(
        options_.channels.perception_camera_pose,
        [this](const std::string&, const uint8_t* data, size_t size, int64_t) {
          OnCameraPose(data, size);
        },
        options_.queue_capacity);
  }
  if (publisher_->publishes_objects() || publisher_->publishes_object_poses()) {
    bus_->Subscribe(
        options_.channels.perception_objects,
        [this](const std::string&, const uint8_t* data, size_t size, int64_t) {
          OnObjects(data, size);
        },
        options_.queue_capacity);
  }
}

void PerceptionDdsBridge::OnCameraPose(const uint8_t* data, size_t size) {
  const std::string& channel = options_.channels.perception_camera_pose;
  BridgeChannelCounts* c = &camera_pose_;
  ++c->received;
  mbslam::camera_pose_t msg{};
  Status st = DecodeLcmMessage(data, size, &msg, max_message_bytes_);
  if (!st.ok()) return Bad(c, channel, st.message());
  CameraPoseSample pose;
  bool renormalised = false;
  st = FromLcm(msg, &pose, &renormalised);
  if (!st.ok()) return Bad(c, channel, st.message());
  if (renormalised) ++c->renormalised;
  const bool tracked = pose.tracking_state == TrackingState::kOk ||
                       pose.tracking_state == TrackingState::kRelocalized;
  if (!tracked && !options_.publish_untracked_poses) {
    ++c->skipped;
    return;
  }
  geometry_msgs::msg::dds_::PoseStamped_ ros;
  st = ToRos2PoseStamped(pose, options_.frame_id, &ros);
  if (!st.ok()) return Bad(c, channel, st.message());
  st = publisher_->Publish(ros);
  if (!st.ok()) return WriteFailed(c, channel, st);
  ++c->published;
}

void PerceptionDdsBridge::OnObjects(const uint8_t* data, size_t size) {
  const std::string& channel = options_.channels.perception_objects;
  BridgeChannelCounts* c = &objects_;
  ++c->received;
  mbslam::objects_t msg{};
  Status st = DecodeLcmMessage(data, size, &msg, max_message_bytes_);
  if (!st.ok()) return Bad(c, channel, st.message());
  ObjectsSample objects;
  int invalid = 0;
  int renormalised = 0;
  std::string invalid_reason;
  st = FromLcm(msg, &objects, &invalid, &invalid_reason, &renormalised);
  if (!st.ok()) return Bad(c, channel, st.message());
  c->renormalised += renormalised;
  if (invalid > 0) {
    c->invalid_objects += invalid;
    c->last_error = invalid_reason;
    if (c->invalid_objects <= 5 || c->invalid_objects % 100 == 0) {
      MBSLAM_LOG(WARNING) << "perception_dds_bridge: " << invalid
                          << " invalid object(s) left out on " << channel << " ("
                          << c->invalid_objects << " so far): " << invalid_reason;
    }
  }
  bool failed = false;
  if (publisher_->publishes_objects()) {
    visualization_msgs::msg::dds_::MarkerArray_ markers;
    st = ToRos2MarkerArray(objects, options_.frame_id, options_.markers, &markers);
    if (!st.ok()) return Bad(c, channel, st.message());
    st = publisher_->Publish(markers);
    if (!st.ok()) {
      WriteFailed(c, channel, st);
      failed = true;
    }
  }
  if (publisher_->publishes_object_poses()) {
    geometry_msgs::msg::dds_::PoseArray_ poses;
    st = ToRos2PoseArray(objects, options_.frame_id, options_.markers, &poses);
    if (!st.ok()) return Bad(c, channel, st.message());
    st = publisher_->Publish(poses);
    if (!st.ok()) {
      WriteFailed(c, channel, st);
      failed = true;
    }
  }
  if (!failed) ++c->published;
}

void PerceptionDdsBridge::Bad(BridgeChannelCounts* counts, const std::string& channel,
                              const std::string& why) {
  ++counts->bad;
  counts->last_error = why;
  if (counts->bad <= 5 || counts->bad % 100 == 0) {
    MBSLAM_LOG(WARNING) << "perception_dds_bridge: bad message #" << counts->bad << " on "
                        << channel << " dropped: " << why;
  }
}

void PerceptionDdsBridge::WriteFailed(BridgeChannelCounts* counts, const std::string& channel,
                                      const Status& status) {
  ++counts->write_failures;
  if (counts->write_failures <= 5 || counts->write_failures % 100 == 0) {
    MBSLAM_LOG(WARNING) << "perception_dds_bridge: " << channel << ": " << status.message();
  }
}

Status PerceptionDdsBridge::Run() {
  const bool is_log = bus_->url().rfind("file://", 0) == 0;
  while (!ShutdownRequested()) {
    const int r = bus_->HandleTimeout(100);
    if (r >= 0) continue;
    if (ShutdownRequested()) break;  // the signal interrupted the wait
    if (!is_log) return Status::Error("LCM: receiving on '" + bus_->url() + "' failed");
    // End of a file:// log: handleTimeout keeps returning at once, so never spin on it.
    if (options_.exit_at_end_of_log) return Status::Ok();
    while (!ShutdownRequested()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return Status::Ok();
}

std::string PerceptionDdsBridge::Summary() const {
  std::ostringstream out;
  const std::pair<const std::string*, const BridgeChannelCounts*> channels[] = {
      {&options_.channels.perception_camera_pose, &camera_pose_},
      {&options_.channels.perception_objects, &objects_}};
  bool first = true;
  for (const auto& [name, c] : channels) {
    if (!first) out << "\n";
    first = false;
    out << *name << ": received " << c->received << ", published " << c->published << ", bad "
        << c->bad << ", skipped " << c->skipped << ", invalid objects " << c->invalid_objects
        << ", renormalised " << c->renormalised << ", DDS write failures " << c->write_failures;
    if (!c->last_error.empty()) out << " (last error: " << c->last_error << ")";
  }
  return out.str();
}

}  // namespace mbslam
