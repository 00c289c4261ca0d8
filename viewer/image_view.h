#ifndef MBSLAM_VIEWER_IMAGE_VIEW_H_
#define MBSLAM_VIEWER_IMAGE_VIEW_H_

// The image view: the camera image with the feature tracks of the same utime (static
// green, moving red, unassigned yellow, occluded blue), their flow from the previous
// image, the moving objects' hulls shaded in the object's colour with id and speed,
// and, for the degenerate cases, epipolar lines from the static world's epipole through
// moving features (a feature moving along its epipolar line is invisible to the
// epipolar constraint; thesis sec. 3.4-3.5).

#include <opencv2/core.hpp>

#include "common/util/status.h"
#include "viewer/render_options.h"
#include "viewer/scene.h"

namespace mbslam {
namespace viewer {

// The largest width or height of a drawn view (px): scale and min_width give way to it.
inline constexpr int kMaxViewDimension = 8192;

struct ImageViewInput {
  cv::Mat image;                         // BGR camera image; empty = a grey canvas
  const TracksData* tracks = nullptr;    // may be null
  const ObjectsData* objects = nullptr;  // for ids and speeds; may be null
  int64_t utime = 0;                     // µs
  std::string note;                      // shown in the header (e.g. why there is no image)
};

// Draws the view (BGR). Never fails on odd data: features outside the image, NaNs and
// degenerate hulls are skipped. With the legend on, a header band sits above the image
// and a legend band below it; `image_top` (optional) receives the header's height (px),
// so a track at (u, v) of an image as wide as the output is drawn at (u, v + image_top).
void RenderImageView(const ImageViewOptions& options, const ImageViewInput& input, cv::Mat* bgr,
                     int* image_top = nullptr);

// The input for the newest complete frame of `scene`: the image is decoded here; an
// image that does not decode gives an error (the view can still be drawn without it).
Status MakeImageViewInput(const SceneState& scene, int max_image_dimension, ImageViewInput* input);

// Pixel classes of the legend.
enum class TrackClass { kStatic, kMoving, kUnassigned, kOccluded };
TrackClass ClassifyTrack(const TrackFeature& track);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_IMAGE_VIEW_H_
