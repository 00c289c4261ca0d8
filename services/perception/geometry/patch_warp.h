#ifndef MBSLAM_SERVICES_PERCEPTION_GEOMETRY_PATCH_WARP_H_
#define MBSLAM_SERVICES_PERCEPTION_GEOMETRY_PATCH_WARP_H_

// The affine patch warp of a feature between two views whose poses are known (thesis
// sec. 2.2: "affine patch warps when the pose is known"): the homography induced by the
// local surface plane at the feature, linearised at the feature. It maps pixel offsets
// around the feature in the reference image to pixel offsets in the current image, so
// that the reference appearance can be matched under perspective change (a ground patch
// seen nearer is stretched vertically twice as much as horizontally).

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Core>

#include "services/perception/geometry/camera.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

// The 2x2 Jacobian d(uv_cur) / d(uv_ref) at `ref_uv` of the map that sends a reference
// pixel along its ray onto the plane through `point_in_world` with normal
// `normal_in_world`, then into the current image (central differences of +-step_px,
// through the cameras' distortion). nullopt when the reference rays graze the plane
// (within `min_incidence` of parallel, as the cosine), meet it behind the camera, or
// land behind the current camera.
std::optional<Eigen::Matrix2d> PlaneInducedAffineWarp(const CameraIntrinsics& intrinsics,
                                                      const Rigid3d& ref_cam_from_world,
                                                      const Rigid3d& cur_cam_from_world, const Eigen::Vector2d& ref_uv,
                                                      const Eigen::Vector3d& point_in_world,
                                                      const Eigen::Vector3d& normal_in_world, double step_px = 2.0,
                                                      double min_incidence = 0.05);

// Singular values of a 2x2 matrix, largest first (closed form).
template <typename Scalar>
Eigen::Matrix<Scalar, 2, 1> SingularValues2x2(const Eigen::Matrix<Scalar, 2, 2>& m) {
  // s1^2 + s2^2 = |m|_F^2 and s1 s2 = |det m|.
  const Scalar f = m.squaredNorm();
  const Scalar d = std::abs(m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0));
  const Scalar root = std::sqrt(std::max(Scalar(0), f * f - Scalar(4) * d * d));
  const Scalar s1 = std::sqrt(Scalar(0.5) * (f + root));
  return Eigen::Matrix<Scalar, 2, 1>(s1, s1 > Scalar(0) ? d / s1 : Scalar(0));
}

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_GEOMETRY_PATCH_WARP_H_
