#include "services/perception/objects/relative_scale.h"

#include <cmath>

namespace mbslam {

std::optional<RelativeScaleEstimate> RelativeScale(double d_bot, double d_sfm, double sigma_bot,
                                                   double sigma_sfm) {
  if (!std::isfinite(d_bot) || !std::isfinite(d_sfm) || !(d_bot > 0.0) || !(d_sfm > 0.0) ||
      !std::isfinite(sigma_bot) || !std::isfinite(sigma_sfm) || sigma_bot < 0.0 ||
      sigma_sfm < 0.0) {
    return std::nullopt;
  }
  RelativeScaleEstimate e;
  e.scale = d_bot / d_sfm;
  e.sigma = e.scale * std::hypot(sigma_bot / d_bot, sigma_sfm / d_sfm);
  return e;
}

Rigid3d ScaledCamFromObject(const Rigid3d& cam_from_obj, double scale) {
  return Rigid3d(cam_from_obj.rotation, scale * cam_from_obj.translation);
}

Rigid3d WorldFromObject(const Rigid3d& cam_from_world, const Rigid3d& cam_from_obj, double scale) {
  return cam_from_world.Inverse() * ScaledCamFromObject(cam_from_obj, scale);
}

Sim3d WorldFromObjectMap(const Rigid3d& cam_from_world, const Rigid3d& cam_from_obj, double scale) {
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  Sim3d sim;
  sim.scale = scale;
  sim.rotation = (world_from_cam.rotation * cam_from_obj.rotation).normalized();
  sim.translation =
      world_from_cam.rotation * (scale * cam_from_obj.translation) + world_from_cam.translation;
  return sim;
}

std::vector<Eigen::Vector3d> ObjectPointsInWorld(const std::vector<Eigen::Vector3d>& points_in_obj,
                                                 const Rigid3d& cam_from_world,
                                                 const Rigid3d& cam_from_obj, double scale) {
  const Sim3d sim = WorldFromObjectMap(cam_from_world, cam_from_obj, scale);
  std::vector<Eigen::Vector3d> out;
  out.reserve(points_in_obj.size());
  for (const Eigen::Vector3d& p : points_in_obj) out.push_back(sim * p);
  return out;
}

Status ObjectTrajectoryInWorld(const std::vector<Rigid3d>& cams_from_world,
                               const std::vector<Rigid3d>& cams_from_obj, double scale,
                               std::vector<Rigid3d>* worlds_from_obj) {
  if (worlds_from_obj == nullptr) return Status::Error("ObjectTrajectoryInWorld: null output");
  if (cams_from_world.size() != cams_from_obj.size()) {
    return Status::Error("ObjectTrajectoryInWorld: pose lists differ in length");
  }
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    return Status::Error("ObjectTrajectoryInWorld: scale must be positive and finite");
  }
  worlds_from_obj->clear();
  worlds_from_obj->reserve(cams_from_world.size());
  for (size_t i = 0; i < cams_from_world.size(); ++i) {
    worlds_from_obj->push_back(WorldFromObject(cams_from_world[i], cams_from_obj[i], scale));
  }
  return Status::Ok();
}

}  // namespace mbslam
