#include "drivers/dds_output_bridge/perception_lcm_input.h"

#include <cmath>

namespace mbslam {
namespace {

bool AllFinite(const double* v, int n) {
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

Status ScaleStateFromLcm(int8_t value, ScaleState* state) {
  if (value == mbslam::camera_pose_t::SCALE_UP_TO_SCALE) {
    *state = ScaleState::kUpToScale;
  } else if (value == mbslam::camera_pose_t::SCALE_METRIC) {
    *state = ScaleState::kMetric;
  } else {
    return Status::Error("unknown scale_state " + std::to_string(value));
  }
  return Status::Ok();
}

Status ObjectFromLcm(const mbslam::object_t& o, ObjectSample* out, bool* renormalised) {
  if (o.state < mbslam::object_t::STATE_DETECTED ||
      o.state > mbslam::object_t::STATE_RECONSTRUCTED) {
    return Status::Error("unknown state " + std::to_string(o.state));
  }
  if (!AllFinite(o.position, 3) || !AllFinite(o.linear_velocity, 3) || !AllFinite(o.extent, 3)) {
    return Status::Error("non-finite position, velocity or extent");
  }
  for (double e : o.extent) {
    if (e < 0.0) return Status::Error("negative extent");
  }
  ObjectSample s;
  s.id = o.id;
  s.state = static_cast<ObjectState>(o.state);
  MBSLAM_RETURN_IF_ERROR(
      QuaternionFromWxyz(o.orientation, &s.world_from_object.rotation, renormalised));
  s.world_from_object.translation = Eigen::Vector3d(o.position[0], o.position[1], o.position[2]);
  s.linear_velocity =
      Eigen::Vector3d(o.linear_velocity[0], o.linear_velocity[1], o.linear_velocity[2]);
  s.extent = Eigen::Vector3d(o.extent[0], o.extent[1], o.extent[2]);
  *out = s;
  return Status::Ok();
}

}  // namespace

Status QuaternionFromWxyz(const double wxyz[4], Eigen::Quaterniond* q, bool* renormalised) {
  *renormalised = false;
  if (!AllFinite(wxyz, 4)) return Status::Error("non-finite quaternion");
  // Eigen's constructor takes (w, x, y, z); its storage is (x, y, z, w).
  const Eigen::Quaterniond raw(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  const double norm = raw.norm();
  if (std::abs(norm - 1.0) <= 1e-6) {
    *q = raw;
    return Status::Ok();
  }
  if (std::abs(norm - 1.0) <= 1e-2) {
    *q = raw.normalized();
    *renormalised = true;
    return Status::Ok();
  }
  return Status::Error("quaternion norm " + std::to_string(norm) + " is not 1");
}

Status FromLcm(const mbslam::camera_pose_t& msg, CameraPoseSample* pose, bool* renormalised) {
  if (!AllFinite(msg.position, 3)) return Status::Error("non-finite camera position");
  if (msg.tracking_state < mbslam::camera_pose_t::TRACKING_NOT_INITIALIZED ||
      msg.tracking_state > mbslam::camera_pose_t::TRACKING_RELOCALIZED) {
    return Status::Error("unknown tracking_state " + std::to_string(msg.tracking_state));
  }
  CameraPoseSample s;
  s.utime = msg.utime;
  s.tracking_state = static_cast<TrackingState>(msg.tracking_state);
  MBSLAM_RETURN_IF_ERROR(ScaleStateFromLcm(msg.scale_state, &s.scale_state));
  MBSLAM_RETURN_IF_ERROR(
      QuaternionFromWxyz(msg.orientation, &s.world_from_cam.rotation, renormalised)
          .WithContext("camera orientation"));
  s.world_from_cam.translation = Eigen::Vector3d(msg.position[0], msg.position[1], msg.position[2]);
  *pose = s;
  return Status::Ok();
}

Status FromLcm(const mbslam::objects_t& msg, ObjectsSample* objects, int* invalid_objects,
               std::string* invalid_reason, int* renormalised) {
  *invalid_objects = 0;
  *renormalised = 0;
  if (msg.num_objects != static_cast<int32_t>(msg.objects.size())) {
    return Status::Error("num_objects " + std::to_string(msg.num_objects) + " but " +
                         std::to_string(msg.objects.size()) + " objects");
  }
  ObjectsSample s;
  s.utime = msg.utime;
  MBSLAM_RETURN_IF_ERROR(ScaleStateFromLcm(msg.scale_state, &s.scale_state));
  s.objects.reserve(msg.objects.size());
  for (const mbslam::object_t& o : msg.objects) {
    ObjectSample object;
    bool renorm = false;
    const Status st = ObjectFromLcm(o, &object, &renorm);
    if (!st.ok()) {
      ++*invalid_objects;
      *invalid_reason = "object " + std::to_string(o.id) + ": " + st.message();
      continue;
    }
    if (renorm) ++*renormalised;
    s.objects.push_back(object);
  }
  *objects = std::move(s);
  return Status::Ok();
}

}  // namespace mbslam
