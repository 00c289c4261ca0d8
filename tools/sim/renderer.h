#ifndef MBSLAM_TOOLS_SIM_RENDERER_H_
#define MBSLAM_TOOLS_SIM_RENDERER_H_

// Offscreen OpenGL (OSMesa, llvmpipe) renderer of a simulator scene. One colour pass
// (textured, Lambert-shaded, optionally multisampled) and one geometry pass that gives,
// at every pixel centre, the body id and the surface point in the camera frame (float),
// from which the mask and the depth map come. Pixel convention as in
// geometry/camera.h: pixel (u, v) has its centre at integer coordinates, v down.

#include <opencv2/core.hpp>

#include <array>
#include <memory>
#include <vector>

#include "common/config/options.h"
#include "common/util/status.h"
#include "services/perception/geometry/camera.h"
#include "services/perception/geometry/rigid3.h"
#include "tools/sim/scene.h"

namespace mbslam {
namespace sim {

struct RendererOptions {
  int antialias_samples = 4;      // multisampling of the colour image: 1 (off) or 4 (count)
  double near_m = 0.05;           // near clipping distance (m); no far plane (reversed z)
  double detail_strength = 0.25;  // contrast of the fine detail texture [0, 1]
  double detail_period_m = 1.7;   // repetition period of the detail texture (m)
  double anisotropy =
      1.0;  // GL anisotropic texture filtering, 1 = off; very slow in llvmpipe (ratio)
  int anisotropic_taps =
      4;  // shader anisotropic filtering: taps along the footprint, 1 = off (count)
  std::array<double, 3> sky_bgr = {0.92, 0.80, 0.62};  // background colour, BGR [0, 1]

  bool Check() const {
    MBSLAM_CHECK_OPTION(antialias_samples == 1 || antialias_samples == 2 || antialias_samples == 4);
    MBSLAM_CHECK_OPTION_GT(near_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(detail_strength, 0.0);
    MBSLAM_CHECK_OPTION_LE(detail_strength, 1.0);
    MBSLAM_CHECK_OPTION_GT(detail_period_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(anisotropy, 1.0);
    MBSLAM_CHECK_OPTION_GE(anisotropic_taps, 1);
    MBSLAM_CHECK_OPTION_LE(anisotropic_taps, 16);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("antialias_samples", &antialias_samples,
      "multisampling of the colour image: 1, 2 or 4 (count)");
    v("near_m", &near_m, "near clipping distance (m)");
    v("detail_strength", &detail_strength, "contrast of the fine detail texture [0, 1]");
    v("detail_period_m", &detail_period_m, "repetition period of the detail texture (m)");
    v("anisotropy", &anisotropy,
      "GL anisotropic texture filtering, 1 = off; very slow in llvmpipe (ratio)");
    v("anisotropic_taps", &anisotropic_taps, "shader anisotropic filtering taps, 1 = off (count)");
    v("sky_bgr", &sky_bgr, "background colour, BGR [0, 1]");
  }
};

class Renderer {
 public:
  // Creates the GL context for images of intrinsics.width x height (no distortion) and
  // uploads the scene's geometry and textures. The scene must outlive the renderer.
  static std::unique_ptr<Renderer> Create(const Scene& scene, const CameraIntrinsics& intrinsics,
                                          const RendererOptions& options, Status* status);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Colour image (CV_8UC3, BGR) with body i at cam_from_body[i] (index into
  // Scene::bodies).
  Status RenderColor(const std::vector<Rigid3d>& cam_from_body, cv::Mat* bgr);

  // Body id per pixel (CV_16UC1; background = 0) and the visible surface point at each
  // pixel centre in the camera frame (CV_32FC3, m; (0, 0, 0) where nothing was hit).
  Status RenderGeometry(const std::vector<Rigid3d>& cam_from_body, cv::Mat* body_id,
                        cv::Mat* points_in_cam);

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_RENDERER_H_
