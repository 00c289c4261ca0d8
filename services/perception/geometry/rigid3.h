#ifndef MBSLAM_SERVICES_PERCEPTION_GEOMETRY_RIGID3_H_
#define MBSLAM_SERVICES_PERCEPTION_GEOMETRY_RIGID3_H_

// Rigid transforms on SE(3), named target_from_source:
//   point_in_cam = cam_from_world * point_in_world.
// Twists are 6-vectors xi = [v; w] (translation part first, then rotation, as in the
// thesis's eq. 4.1 and in every covariance of the message contract). The exponential
// map is the closed form of Barfoot / Murray-Li-Sastry; increments are applied on the
// left: T' = Exp(xi) * T.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mbslam {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

// Skew-symmetric matrix: Hat(a) * b = a x b.
Eigen::Matrix3d Hat(const Eigen::Vector3d& a);

// SO(3) exponential / logarithm (axis-angle vectors, rad). LogSO3 returns |w| <= pi.
Eigen::Matrix3d ExpSO3(const Eigen::Vector3d& w);
Eigen::Vector3d LogSO3(const Eigen::Matrix3d& R);
// Left Jacobian of SO(3) and its inverse.
Eigen::Matrix3d LeftJacobianSO3(const Eigen::Vector3d& w);
Eigen::Matrix3d LeftJacobianInverseSO3(const Eigen::Vector3d& w);

struct Rigid3d {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3d() = default;
  Rigid3d(const Eigen::Quaterniond& q, const Eigen::Vector3d& t) : rotation(q.normalized()), translation(t) {}
  Rigid3d(const Eigen::Matrix3d& R, const Eigen::Vector3d& t)
      : rotation(Eigen::Quaterniond(R).normalized()), translation(t) {}

  static Rigid3d Identity() { return Rigid3d(); }

  Rigid3d Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Rigid3d(inv, -(inv * translation));
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation * point + translation;
  }
  Rigid3d operator*(const Rigid3d& other) const {
    return Rigid3d(rotation * other.rotation, rotation * other.translation + translation);
  }
  Eigen::Matrix3d RotationMatrix() const { return rotation.toRotationMatrix(); }
  Eigen::Matrix4d ToMatrix() const;
  Eigen::Matrix<double, 3, 4> ToMatrix3x4() const;

  // exp: se(3) -> SE(3) and its inverse, xi = [v; w].
  static Rigid3d Exp(const Vector6d& xi);
  Vector6d Log() const;

  // Adjoint: Ad(T) * xi maps a twist in the source frame to the target frame, so that
  // T * Exp(xi) = Exp(Ad(T) xi) * T.
  Matrix6d Adjoint() const;

  // The transform a fraction `t` of the way from `a` to `b` along the geodesic
  // (t = 0 -> a, t = 1 -> b): a * Exp(t * Log(a^-1 b)).
  static Rigid3d Interpolate(const Rigid3d& a, const Rigid3d& b, double t);

  bool IsFinite() const {
    return rotation.coeffs().allFinite() && translation.allFinite();
  }
};

// Rotation angle (rad) and translation distance between two transforms.
double RotationDistance(const Rigid3d& a, const Rigid3d& b);
double TranslationDistance(const Rigid3d& a, const Rigid3d& b);

// Similarity transform b = s * R * a + t (for Sim(3) alignment and relative scale).
struct Sim3d {
  double scale = 1.0;
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    return scale * (rotation * p) + translation;
  }
  // Applies the similarity to a pose world_from_x: rotation composes, translation is
  // scaled, rotated and shifted.
  Rigid3d operator*(const Rigid3d& pose) const {
    return Rigid3d(rotation * pose.rotation, scale * (rotation * pose.translation) + translation);
  }
  Sim3d Inverse() const;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_GEOMETRY_RIGID3_H_
