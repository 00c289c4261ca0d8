#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_TRIANGULATION_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_TRIANGULATION_H_

#include <optional>

#include <Eigen/Core>

#include "services/perception/geometry/rigid3.h"

namespace mbslam {

// Linear (DLT) triangulation of a point seen at normalised coordinates xy_a, xy_b by
// cameras cam_a_from_world, cam_b_from_world. nullopt if degenerate.
std::optional<Eigen::Vector3d> TriangulateDlt(const Rigid3d& cam_a_from_world, const Eigen::Vector2d& xy_a,
                                              const Rigid3d& cam_b_from_world, const Eigen::Vector2d& xy_b);

// Angle (rad) between the rays from the two camera centres to the point.
double ParallaxAngle(const Rigid3d& cam_a_from_world, const Rigid3d& cam_b_from_world,
                     const Eigen::Vector3d& point_in_world);

// Reprojection error (normalised units) of a world point in a camera; +inf behind it.
double ReprojectionError(const Rigid3d& cam_from_world, const Eigen::Vector3d& point_in_world,
                         const Eigen::Vector2d& xy);

// Jacobians of the projection x = (p.x / p.z, p.y / p.z) with p = T * X, w.r.t. a left
// perturbation of T (2x6, twist [v; w]) and w.r.t. X (2x3). False behind the camera.
bool ProjectionJacobians(const Rigid3d& cam_from_world, const Eigen::Vector3d& point_in_world,
                         Eigen::Vector2d* projection, Eigen::Matrix<double, 2, 6>* d_pose,
                         Eigen::Matrix<double, 2, 3>* d_point);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_TRIANGULATION_H_
