#ifndef MBSLAM_VIEWER_VIEW_CAMERA_H_
#define MBSLAM_VIEWER_VIEW_CAMERA_H_

// The virtual camera of the 3D view and its automatic framing. The view frame follows
// the image convention (x right, y down, z along the viewing direction); pixels have
// their centres at integer (u, v), v down, as in the saved PNG.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "viewer/render_options.h"
#include "viewer/scene.h"

namespace mbslam {
namespace viewer {

struct ViewCamera {
  Eigen::Isometry3d view_from_world = Eigen::Isometry3d::Identity();
  bool orthographic = false;
  double fov_y_rad = 1.0471975511965976;  // perspective: vertical field of view (rad)
  double ortho_half_height = 1.0;         // orthographic: half the visible height (units)
  double near = 0.01;                     // near clipping distance (units)
  double far = 100.0;                     // far clipping distance (units)
  int width = 1280, height = 720;         // px

  // OpenGL clip coordinates (x right, y up, depth in [-w, w]) from the view frame and
  // from the world.
  Eigen::Matrix4d ClipFromView() const;
  Eigen::Matrix4d ClipFromWorld() const;
  // Pixel of a world point; false when it is outside the depth range or the image.
  bool Project(const Eigen::Vector3d& point_in_world, Eigen::Vector2d* pixel) const;
  Eigen::Vector3d eye_in_world() const { return view_from_world.inverse().translation(); }
  // World length covered by one pixel at `point_in_world` (units / px).
  double UnitsPerPixel(const Eigen::Vector3d& point_in_world) const;
};

// A camera at `eye` looking at `target`, with `up_hint` pointing up on the screen
// (any other direction is used when the two are parallel).
ViewCamera LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
                  const Eigen::Vector3d& up_hint);

// "Up" in the world: the ground plane's normal when the map has one, else -y (the SLAM
// frame's camera y axis points down).
Eigen::Vector3d UpDirection(const MapData& map);

// A horizontal (perpendicular to `up`) unit vector close to `direction`; a fixed
// perpendicular of `up` when `direction` is (nearly) vertical.
Eigen::Vector3d Horizontal(const Eigen::Vector3d& direction, const Eigen::Vector3d& up);

// Bounds of the scene for framing: map points between the given percentiles per axis
// (outliers ignored), plus the trajectory, keyframes, current camera and objects. An
// empty scene gives a unit box at the origin.
Eigen::AlignedBox3d SceneBounds(const SceneState& scene, double percentile);

// Typical distance of the map points from the current camera (their median), used to
// size the follow view and the frusta; falls back on the bounds' size, then 1.
double LocalScale(const SceneState& scene, const Eigen::AlignedBox3d& bounds);

// The camera of the configured mode (follow / top_down / fixed) for this scene.
ViewCamera ComputeViewCamera(const View3dOptions& options, const SceneState& scene);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_VIEW_CAMERA_H_
