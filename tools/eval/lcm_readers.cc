#include "tools/eval/lcm_readers.h"

#include "common/lcm/lcm_log.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/objects_t.hpp"

namespace mbslam {
namespace eval {
namespace {

// Pose from a message's position[3] and orientation[4] ([w, x, y, z]).
Rigid3d MessagePose(const double position[3], const double orientation[4]) {
  return Rigid3d(Eigen::Quaterniond(orientation[0], orientation[1], orientation[2], orientation[3]),
                 Eigen::Vector3d(position[0], position[1], position[2]));
}

template <typename Msg>
bool Decode(const LcmLogEvent& e, Msg* msg) {
  return msg->decode(e.data.data(), 0, static_cast<int>(e.data.size())) >= 0;
}

}  // namespace

Status ReadCameraPoseLog(const std::string& path, const std::string& channel, CameraPoseLog* log) {
  *log = CameraPoseLog();
  Status status;
  auto reader = LcmLogReader::Open(path, &status);
  if (!reader) {
    return status;
  }
  LcmLogEvent e;
  while (reader->Next(&e)) {
    if (e.channel != channel) {
      continue;
    }
    mbslam::camera_pose_t msg{};
    if (!Decode(e, &msg)) {
      ++log->num_undecodable;
      continue;
    }
    ++log->num_messages;
    if (msg.scale_state == mbslam::camera_pose_t::SCALE_METRIC) {
      ++log->num_metric;
    }
    if (msg.tracking_state == mbslam::camera_pose_t::TRACKING_OK ||
        msg.tracking_state == mbslam::camera_pose_t::TRACKING_RELOCALIZED) {
      const Rigid3d pose = MessagePose(msg.position, msg.orientation);
      if (pose.IsFinite()) {
        log->tracked.push_back({msg.utime, pose});
      }
    }
  }
  SortByTime(&log->tracked);
  return Status::Ok();
}

Status ReadGroundTruthLog(const std::string& path, const std::string& channel,
                          GroundTruthLog* log) {
  *log = GroundTruthLog();
  Status status;
  auto reader = LcmLogReader::Open(path, &status);
  if (!reader) {
    return status;
  }
  LcmLogEvent e;
  while (reader->Next(&e)) {
    if (e.channel != channel) {
      continue;
    }
    mbslam::ground_truth_t msg{};
    if (!Decode(e, &msg)) {
      return Status::Error(path + ": undecodable ground_truth_t on " + channel);
    }
    ++log->num_messages;
    log->source = msg.source;
    if (msg.has_camera) {
      log->camera.push_back({msg.utime, MessagePose(msg.cam_position, msg.cam_orientation)});
    }
    for (const auto& b : msg.bodies) {
      BodyTruth& body = log->bodies[b.id];
      body.id = b.id;
      body.name = b.name;
      body.extent = Eigen::Vector3d(b.extent[0], b.extent[1], b.extent[2]);
      body.poses.push_back({msg.utime, MessagePose(b.position, b.orientation)});
    }
  }
  SortByTime(&log->camera);
  for (auto& b : log->bodies) {
    SortByTime(&b.second.poses);
  }
  if (log->num_messages == 0) {
    return Status::Error(path + ": no ground_truth_t on channel " + channel);
  }
  return Status::Ok();
}

Status ReadObjectsLog(const std::string& path, const std::string& channel,
                      std::map<int, ObjectEstimate>* objects, int* num_messages) {
  objects->clear();
  if (num_messages) {
    *num_messages = 0;
  }
  Status status;
  auto reader = LcmLogReader::Open(path, &status);
  if (!reader) {
    return status;
  }
  LcmLogEvent e;
  while (reader->Next(&e)) {
    if (e.channel != channel) {
      continue;
    }
    mbslam::objects_t msg{};
    if (!Decode(e, &msg)) {
      return Status::Error(path + ": undecodable objects_t on " + channel);
    }
    if (num_messages) {
      ++*num_messages;
    }
    for (const auto& o : msg.objects) {
      ObjectEstimate& est = (*objects)[o.id];
      est.id = o.id;
      // An object published from the segmentation alone (no filter yet: no particles, no
      // volumes) has an id and a hull but no position: its zero position is not an
      // estimate and is not scored.
      if (o.num_particles <= 0 && o.volumes.empty()) continue;
      ObjectSample s;
      s.utime = msg.utime;
      s.position = Eigen::Vector3d(o.position[0], o.position[1], o.position[2]);
      s.depth = o.depth > 0.0 ? o.depth : -1.0;
      for (const auto& v : o.volumes) {
        PredictedVolume pv;
        pv.utime = v.utime;
        pv.horizon_us = v.horizon_us;
        pv.center = Eigen::Vector3d(v.center[0], v.center[1], v.center[2]);
        pv.orientation = Eigen::Quaterniond(v.orientation[0], v.orientation[1], v.orientation[2],
                                            v.orientation[3]);
        pv.orientation.normalize();
        pv.half_extent = Eigen::Vector3d(v.half_extent[0], v.half_extent[1], v.half_extent[2]);
        pv.probability = v.probability;
        s.volumes.push_back(pv);
      }
      est.samples.push_back(std::move(s));
    }
  }
  return Status::Ok();
}

Status CountLogEvents(const std::string& path, const std::string& channel, int* count) {
  *count = 0;
  Status status;
  auto reader = LcmLogReader::Open(path, &status);
  if (!reader) {
    return status;
  }
  LcmLogEvent e;
  while (reader->Next(&e)) {
    if (e.channel == channel) {
      ++*count;
    }
  }
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
