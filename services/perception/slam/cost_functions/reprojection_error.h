#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_COST_FUNCTIONS_REPROJECTION_ERROR_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_COST_FUNCTIONS_REPROJECTION_ERROR_H_

// Ceres cost functions of the bundle adjustment. Only the factory functions are
// declared here; the templated functors (and Ceres' autodiff) stay in the .cc so
// that including this header is cheap.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ceres {
class CostFunction;
}

namespace mbslam {

// Reprojection error in pixels of a point X (3, world) seen at normalised coordinates
// `xy` by a camera with rotation q (4, Eigen order x y z w, cam_from_world) and
// translation t (3):
//   p = R(q) X + t,  r = focal * (p.xy / p.z - xy).
// Parameter blocks: q [4], t [3], X [3]; residuals: 2.
ceres::CostFunction* CreateReprojectionError(const Eigen::Vector2d& xy, double focal_px);

// Relative-translation prior from odometry between two keyframes a and b (metric
// scale): the camera displacement expressed in a's frame must match the odometry's,
//   c_x = -R_x^T t_x (camera centre in world),
//   r = (R_a (c_b - c_a) - d_ab_in_a) / sigma,
// Parameter blocks: q_a [4], t_a [3], q_b [4], t_b [3]; residuals: 3.
ceres::CostFunction* CreateOdometryTranslationPrior(const Eigen::Vector3d& d_ab_in_a, double sigma_m);

// Relative-rotation prior between two keyframes a and b: the rotation from a's camera to
// b's must match `b_from_a` (e.g. the camera's own rotation when the mapped body does not
// turn): r = 2 vec(q_b q_a^-1 b_from_a^-1) / sigma (the rotation angle error for small
// errors, rad / rad). Parameter blocks: q_a [4], q_b [4]; residuals: 3.
ceres::CostFunction* CreateRelativeRotationPrior(const Eigen::Quaterniond& b_from_a, double sigma_rad);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_COST_FUNCTIONS_REPROJECTION_ERROR_H_
