#include "drivers/odometry_bridge/odometry_sample.h"

#include <cmath>
#include <sstream>

#include "common/lcm/wire_check.h"
#include "mbslam/pose_t.hpp"

namespace mbslam {

Status OdometryQuaternion(double x, double y, double z, double w, Eigen::Quaterniond* q,
                          bool* renormalised) {
  *renormalised = false;
  const double norm = std::sqrt(x * x + y * y + z * z + w * w);
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-2) {
    std::ostringstream os;
    os << "orientation quaternion has norm " << norm << " (not a rotation)";
    return Status::Error(os.str());
  }
  *q = Eigen::Quaterniond(w, x, y, z);
  if (std::abs(norm - 1.0) > 1e-6) {
    q->normalize();
    *renormalised = true;
  }
  return Status::Ok();
}

Status ValidateOdometrySample(const OdometrySample& s) {
  if (!s.odom_from_base.translation.allFinite()) return Status::Error("non-finite position");
  if (!s.odom_from_base.rotation.coeffs().allFinite() ||
      std::abs(s.odom_from_base.rotation.norm() - 1.0) > 1e-2) {
    return Status::Error("orientation is not a unit quaternion");
  }
  if (!s.linear_velocity.allFinite() || !s.angular_velocity.allFinite()) {
    return Status::Error("non-finite twist");
  }
  for (double v : s.pose_covariance) {
    if (!std::isfinite(v)) return Status::Error("non-finite pose covariance");
  }
  for (double v : s.twist_covariance) {
    if (!std::isfinite(v)) return Status::Error("non-finite twist covariance");
  }
  return Status::Ok();
}

Status OdometryFromPoseMessage(const uint8_t* data, size_t size, const OdometrySample* previous,
                               bool derive_twist, OdometrySample* sample) {
  mbslam::pose_t pose{};
  MBSLAM_RETURN_IF_ERROR(DecodeLcmMessage(data, size, &pose, size_t{1} << 16));
  OdometrySample s;
  s.utime = pose.utime;
  s.frame_id = pose.target_frame;
  s.child_frame_id = pose.source_frame;
  s.odom_from_base.translation = Eigen::Vector3d(pose.position[0], pose.position[1], pose.position[2]);
  bool renormalised = false;
  MBSLAM_RETURN_IF_ERROR(OdometryQuaternion(pose.orientation[1], pose.orientation[2],
                                            pose.orientation[3], pose.orientation[0],
                                            &s.odom_from_base.rotation, &renormalised));
  s.seq = previous ? previous->seq + 1 : 0;
  if (derive_twist && previous && s.utime > previous->utime) {
    // In double: the difference of two message times can exceed int64.
    const double dt_s =
        (static_cast<double>(s.utime) - static_cast<double>(previous->utime)) * 1e-6;
    TwistFromPoses(previous->odom_from_base, s.odom_from_base, dt_s, &s.linear_velocity,
                   &s.angular_velocity);
  }
  *sample = std::move(s);
  return Status::Ok();
}

void ToOdometryMessage(const OdometrySample& s, mbslam::odometry_t* msg) {
  msg->utime = s.utime;
  msg->seq = s.seq;
  msg->frame_id = s.frame_id;
  msg->child_frame_id = s.child_frame_id;
  for (int i = 0; i < 3; ++i) {
    msg->position[i] = s.odom_from_base.translation[i];
    msg->linear_velocity[i] = s.linear_velocity[i];
    msg->angular_velocity[i] = s.angular_velocity[i];
  }
  // Rigid3d normalises in its constructor; copy the stored coefficients as they are.
  const Eigen::Quaterniond& q = s.odom_from_base.rotation;
  msg->orientation[0] = q.w();
  msg->orientation[1] = q.x();
  msg->orientation[2] = q.y();
  msg->orientation[3] = q.z();
  for (size_t i = 0; i < 36; ++i) {
    msg->pose_covariance[i] = s.pose_covariance[i];
    msg->twist_covariance[i] = s.twist_covariance[i];
  }
}

Status FromOdometryMessage(const mbslam::odometry_t& msg, OdometrySample* s) {
  OdometrySample out;
  out.utime = msg.utime;
  out.seq = msg.seq;
  out.frame_id = msg.frame_id;
  out.child_frame_id = msg.child_frame_id;
  Eigen::Quaterniond q;
  bool renormalised = false;
  MBSLAM_RETURN_IF_ERROR(OdometryQuaternion(msg.orientation[1], msg.orientation[2],
                                            msg.orientation[3], msg.orientation[0], &q,
                                            &renormalised));
  out.odom_from_base.rotation = q;
  out.odom_from_base.translation = Eigen::Vector3d(msg.position[0], msg.position[1], msg.position[2]);
  out.linear_velocity = Eigen::Vector3d(msg.linear_velocity[0], msg.linear_velocity[1], msg.linear_velocity[2]);
  out.angular_velocity =
      Eigen::Vector3d(msg.angular_velocity[0], msg.angular_velocity[1], msg.angular_velocity[2]);
  for (size_t i = 0; i < 36; ++i) {
    out.pose_covariance[i] = msg.pose_covariance[i];
    out.twist_covariance[i] = msg.twist_covariance[i];
  }
  MBSLAM_RETURN_IF_ERROR(ValidateOdometrySample(out));
  *s = out;
  return Status::Ok();
}

void TwistFromPoses(const Rigid3d& previous, const Rigid3d& current, double dt_s,
                    Eigen::Vector3d* linear_velocity, Eigen::Vector3d* angular_velocity) {
  if (!(dt_s > 0.0)) {
    linear_velocity->setZero();
    angular_velocity->setZero();
    return;
  }
  // current = previous * Exp(xi * dt) with xi the body twist; Log of the relative pose.
  const Vector6d xi = (previous.Inverse() * current).Log() / dt_s;
  *linear_velocity = xi.head<3>();
  *angular_velocity = xi.tail<3>();
}

}  // namespace mbslam
