#ifndef MBSLAM_VIEWER_VIEW3D_RENDERER_H_
#define MBSLAM_VIEWER_VIEW3D_RENDERER_H_

// The 3D map view, drawn offscreen with OSMesa in the thesis's legend (Kundu 2011,
// fig. 6.1): static map points coloured by height above the ground plane, the camera
// trajectory in red with the current camera and the keyframes as frusta, every moving
// object's points and trajectory in its own colour, the bearing-only tracker's
// particles in green, occupied voxels, and the predicted volumes as shaded,
// semi-transparent boxes (fading with the horizon). A header and a legend are drawn
// on top.

#include <opencv2/core.hpp>

#include <memory>
#include <string>

#include "common/util/status.h"
#include "viewer/render_options.h"
#include "viewer/scene.h"
#include "viewer/view_camera.h"

namespace mbslam {
namespace viewer {

// Height of a world point above the ground plane when the map has one, else along -y
// (map units), and the heights that span the colour scale.
struct HeightScale {
  Eigen::Vector3d normal = Eigen::Vector3d(0.0, -1.0, 0.0);
  double offset = 0.0;
  double low = 0.0, high = 1.0;  // heights at the ends of the colour scale
  double Height(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
  double Normalized(const Eigen::Vector3d& p) const { return (Height(p) - low) / (high - low); }
};
HeightScale ComputeHeightScale(const View3dOptions& options, const MapData& map);

class View3dRenderer {
 public:
  static std::unique_ptr<View3dRenderer> Create(const View3dOptions& options, Status* status);
  ~View3dRenderer();
  View3dRenderer(const View3dRenderer&) = delete;
  View3dRenderer& operator=(const View3dRenderer&) = delete;

  // Renders the scene from the configured camera mode (BGR, options.width x height).
  Status Render(const SceneState& scene, cv::Mat* bgr);
  // Renders from the given camera (its size must be the options' size).
  Status Render(const SceneState& scene, const ViewCamera& camera, cv::Mat* bgr);

  // GL renderer and version, for logs.
  const std::string& gl_description() const;

 private:
  struct Impl;
  explicit View3dRenderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_VIEW3D_RENDERER_H_
