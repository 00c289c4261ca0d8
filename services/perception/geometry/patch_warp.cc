#include "services/perception/geometry/patch_warp.h"

#include <cmath>

namespace mbslam {

std::optional<Eigen::Matrix2d> PlaneInducedAffineWarp(const CameraIntrinsics& intrinsics,
                                                      const Rigid3d& ref_cam_from_world,
                                                      const Rigid3d& cur_cam_from_world, const Eigen::Vector2d& ref_uv,
                                                      const Eigen::Vector3d& point_in_world,
                                                      const Eigen::Vector3d& normal_in_world, double step_px,
                                                      double min_incidence) {
  const double nn = normal_in_world.norm();
  if (!(nn > 0.0) || !(step_px > 0.0) || !ref_uv.allFinite() || !point_in_world.allFinite()) return std::nullopt;
  const Eigen::Vector3d n = normal_in_world / nn;
  const Rigid3d world_from_ref = ref_cam_from_world.Inverse();
  const Eigen::Vector3d centre = world_from_ref.translation;
  // A reference pixel -> its ray's point on the plane -> the current image.
  auto transfer = [&](const Eigen::Vector2d& uv) -> std::optional<Eigen::Vector2d> {
    const Eigen::Vector3d ray = world_from_ref.rotation * intrinsics.Unproject(uv);
    const double cos_incidence = n.dot(ray);
    if (std::abs(cos_incidence) < min_incidence) return std::nullopt;
    const double lambda = n.dot(point_in_world - centre) / cos_incidence;
    if (!(lambda > 0.0)) return std::nullopt;
    const Eigen::Vector3d in_cur = cur_cam_from_world * (centre + lambda * ray);
    if (!(in_cur.z() > 0.0)) return std::nullopt;
    const Eigen::Vector2d uv_cur = intrinsics.Project(in_cur);
    if (!uv_cur.allFinite()) return std::nullopt;
    return uv_cur;
  };
  Eigen::Matrix2d jacobian;
  for (int axis = 0; axis < 2; ++axis) {
    Eigen::Vector2d step = Eigen::Vector2d::Zero();
    step[axis] = step_px;
    const std::optional<Eigen::Vector2d> plus = transfer(ref_uv + step);
    const std::optional<Eigen::Vector2d> minus = transfer(ref_uv - step);
    if (!plus || !minus) return std::nullopt;
    jacobian.col(axis) = (*plus - *minus) / (2.0 * step_px);
  }
  if (!jacobian.allFinite()) return std::nullopt;
  return jacobian;
}

}  // namespace mbslam
