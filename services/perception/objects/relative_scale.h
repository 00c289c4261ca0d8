#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_RELATIVE_SCALE_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_RELATIVE_SCALE_H_

// The relative scale of a reconstructed moving object (thesis sec. 6.1). The object's own
// SLAM gives cam_from_obj = [R_co | t_co] and its points in its own, unknown scale; the
// static SLAM gives cam_from_world = [R_cw | t_cw]. Every scale s gives a trajectory that
// explains the images,
//   world_from_obj(s) = world_from_cam * [R_co | s t_co]:
//   R_wo = R_cw^T R_co,  t_wo(s) = R_cw^T (s t_co - t_cw),
// and an object map point x_obj (object map units) is s * x_obj in metric object
// coordinates. The bearing-only tracker fixes s = d_BOT / d_SfM: its depth of the tracked
// point over that point's depth in the object's reconstruction (both along the optical
// axis of the same image).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct RelativeScaleEstimate {
  double scale = 0.0;  // world units per object map unit
  double sigma = 0.0;  // standard deviation of scale

  double relative_sigma() const { return scale > 0.0 ? sigma / scale : 0.0; }
  // The scale is certain enough to place the object's map in the world.
  bool IsReliable(double max_relative_sigma) const {
    return scale > 0.0 && relative_sigma() <= max_relative_sigma;
  }
};

// s = d_bot / d_sfm with first-order propagation of independent errors:
//   sigma_s = s * sqrt((sigma_bot / d_bot)^2 + (sigma_sfm / d_sfm)^2).
// nullopt for non-positive or non-finite depths, or negative / non-finite sigmas.
std::optional<RelativeScaleEstimate> RelativeScale(double d_bot, double d_sfm, double sigma_bot,
                                                   double sigma_sfm = 0.0);

// [R_co | s t_co]: the object's pose in metric object coordinates.
Rigid3d ScaledCamFromObject(const Rigid3d& cam_from_obj, double scale);

// world_from_obj(s) = world_from_cam * [R_co | s t_co]; maps metric object coordinates
// (s * x_obj) into the world.
Rigid3d WorldFromObject(const Rigid3d& cam_from_world, const Rigid3d& cam_from_obj, double scale);

// The similarity that maps object map points (object map units) into the world:
// x_world = world_from_cam * (s * (cam_from_obj * x_obj)).
Sim3d WorldFromObjectMap(const Rigid3d& cam_from_world, const Rigid3d& cam_from_obj, double scale);

// The object's map points in the world at the time of (cam_from_world, cam_from_obj).
std::vector<Eigen::Vector3d> ObjectPointsInWorld(const std::vector<Eigen::Vector3d>& points_in_obj,
                                                 const Rigid3d& cam_from_world,
                                                 const Rigid3d& cam_from_obj, double scale);

// The object's trajectory world_from_obj(s) from paired static and object camera poses
// (same images). Fails on different lengths or a non-positive scale.
Status ObjectTrajectoryInWorld(const std::vector<Rigid3d>& cams_from_world,
                               const std::vector<Rigid3d>& cams_from_obj, double scale,
                               std::vector<Rigid3d>* worlds_from_obj);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_RELATIVE_SCALE_H_
