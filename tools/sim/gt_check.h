#ifndef MBSLAM_TOOLS_SIM_GT_CHECK_H_
#define MBSLAM_TOOLS_SIM_GT_CHECK_H_

// Ground-truth consistency of rendered frames: do the ground-truth poses, intrinsics,
// surface points, masks and depth maps tell the same story?
//
// 1. Surface samples: every ground-truth 3D point of every body is projected with the
//    ground-truth poses and intrinsics. If it is visible (a double-precision ray cast
//    through its projection hits that body at its depth), the rendered mask must carry
//    the body's id at the pixel containing the projection (or, within half a pixel of a
//    silhouette, at an adjacent pixel: the "label error" is the distance in pixels from
//    the projection to the nearest pixel of its body), and the rendered surface must
//    pass through the point exactly where it projects: the renderer's per-pixel 3D
//    points around the projection are fitted with an affine map of pixel coordinates,
//    and the pixel position at which that surface meets the point is compared with the
//    projection ("reprojection error", sub-pixel).
// 2. Pixels: on a grid of pixel centres, the body id and depth of the render must match
//    a ray cast into the scene's geometry (depth along the optical axis).

#include <cstdint>
#include <string>

#include "common/config/options.h"
#include "common/util/status.h"
#include "tools/sim/simulator.h"

namespace mbslam {
namespace sim {

struct GtCheckOptions {
  int max_samples_per_body = 3000;  // ground-truth points checked per body and frame (count)
  int pixel_stride = 4;             // ray-cast every n-th pixel in x and y (px)
  double border_px = 2.0;           // ignore projections closer than this to the image border (px)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(max_samples_per_body, 1);
    MBSLAM_CHECK_OPTION_GE(pixel_stride, 1);
    MBSLAM_CHECK_OPTION_GE(border_px, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("max_samples_per_body", &max_samples_per_body,
      "ground-truth points checked per body and frame (count)");
    v("pixel_stride", &pixel_stride, "ray-cast every n-th pixel in x and y (px)");
    v("border_px", &border_px, "ignore projections closer than this to the image border (px)");
  }
};

struct GtCheckReport {
  int frames = 0;
  // Surface samples.
  int64_t samples_visible = 0;         // visible samples that were checked (count)
  int64_t samples_visible_moving = 0;  // ... of them on moving bodies (count)
  int64_t label_failures = 0;          // visible samples with label error > 0.5 px (count)
  double label_max_px = 0.0;           // largest label error (px)
  int64_t reprojection_samples = 0;    // samples in planar 3x3 neighbourhoods (count)
  double reprojection_max_px = 0.0;    // largest sub-pixel reprojection error (px)
  double reprojection_rms_px = 0.0;    // RMS of it (px)
  double surface_max_distance_m =
      0.0;  // largest distance of a sample from the rendered surface (m)
  double depth_at_sample_max_rel =
      0.0;  // largest |rendered depth - sample depth| / depth at interior samples
  // Pixel grid.
  int64_t pixels = 0;                  // pixels ray-cast (count)
  int64_t pixel_label_mismatches = 0;  // rendered id != ray-cast id (count)
  int64_t pixel_label_mismatches_on_edges =
      0;                                     // ... of them within 0.02 px of a silhouette (count)
  int64_t pixel_depth_skipped_on_edges = 0;  // same id, depth of a surface 0.02 px away (count)
  int64_t pixel_depth_grazing =
      0;  // grazing views (depth changes > 1 % per pixel) off by > 1e-5 (count)
  double depth_max_abs_error_m =
      0.0;  // largest |rendered - ray-cast depth|, not at grazing views (m)
  double depth_max_rel_error = 0.0;  // largest relative depth error, not at grazing views
  double depth_max_error_px = 0.0;  // largest depth error as an image displacement, all pixels (px)
  double pixel_backprojection_max_px =
      0.0;  // largest |project(rendered point) - pixel centre| (px)

  // The headline figure: max(label_max_px, reprojection_max_px).
  double MaxErrorPx() const {
    return label_max_px > reprojection_max_px ? label_max_px : reprojection_max_px;
  }
  void Merge(const GtCheckReport& other);
  std::string ToJson() const;
};

// Checks one frame rendered with RenderFrame (image not needed, geometry required) and
// adds to `report`.
Status CheckFrameGroundTruth(const Simulator& sim, const SimFrame& frame,
                             const GtCheckOptions& options, GtCheckReport* report);

}  // namespace sim
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_SIM_GT_CHECK_H_
