#ifndef MBSLAM_VIEWER_RENDER_OPTIONS_H_
#define MBSLAM_VIEWER_RENDER_OPTIONS_H_

// Options of the viewer's rendering core (no LCM, no GL in this header): what the scene
// remembers, the 3D map view and the image view. viewer_options.h adds the process
// options and the channel names on top.

#include <array>
#include <string>

#include "common/config/options.h"

namespace mbslam {
namespace viewer {

// What the viewer remembers between messages.
struct SceneOptions {
  int max_trajectory_points = 100000;        // camera poses kept for the trajectory (count)
  int max_object_trajectory_points = 20000;  // positions kept per object trajectory (count)
  int max_object_trajectories =
      256;                         // objects whose trajectory is kept; oldest dropped first (count)
  int image_buffer = 16;           // CAMERA_IMAGE messages kept to match tracks by utime (count)
  int tracks_buffer = 16;          // PERCEPTION_TRACKS / PERCEPTION_OBJECTS messages kept (count)
  int max_voxels = 300000;         // occupied voxels drawn at most; the rest are counted (count)
  int max_image_dimension = 8192;  // images wider or taller than this are rejected (px)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(max_trajectory_points, 1);
    MBSLAM_CHECK_OPTION_GT(max_object_trajectory_points, 1);
    MBSLAM_CHECK_OPTION_GT(max_object_trajectories, 0);
    MBSLAM_CHECK_OPTION_GT(image_buffer, 0);
    MBSLAM_CHECK_OPTION_GT(tracks_buffer, 0);
    MBSLAM_CHECK_OPTION_GE(max_voxels, 0);
    MBSLAM_CHECK_OPTION_GT(max_image_dimension, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("max_trajectory_points", &max_trajectory_points,
      "camera poses kept for the trajectory (count)");
    v("max_object_trajectory_points", &max_object_trajectory_points,
      "positions kept per object trajectory (count)");
    v("max_object_trajectories", &max_object_trajectories,
      "objects whose trajectory is kept, oldest dropped first (count)");
    v("image_buffer", &image_buffer, "CAMERA_IMAGE messages kept to match tracks by utime (count)");
    v("tracks_buffer", &tracks_buffer,
      "PERCEPTION_TRACKS / PERCEPTION_OBJECTS messages kept (count)");
    v("max_voxels", &max_voxels, "occupied voxels drawn at most (count)");
    v("max_image_dimension", &max_image_dimension, "larger images are rejected (px)");
  }
};

// The 3D map view (OSMesa).
struct View3dOptions {
  int width = 1280;                                        // snapshot width (px)
  int height = 720;                                        // snapshot height (px)
  int antialias_samples = 4;                               // multisampling: 1 (off), 2 or 4 (count)
  std::array<double, 3> background_rgb = {1.0, 1.0, 1.0};  // background colour, RGB [0, 1]
  std::string camera_mode = "follow";                      // follow | top_down | fixed
  double fov_deg = 60.0;  // vertical field of view of the perspective modes (deg)
  double follow_distance =
      0.0;  // follow: eye distance behind the camera (map units); 0 = auto from the data
  double follow_height =
      0.0;  // follow: eye height above the camera along "up" (map units); 0 = auto
  double follow_look_ahead =
      0.0;  // follow: look-at point ahead of the camera (map units); 0 = auto
  std::array<double, 3> fixed_position = {0.0, -10.0,
                                          -10.0};  // fixed: eye position in the world (map units)
  std::array<double, 3> fixed_look_at = {0.0, 0.0, 10.0};  // fixed: point looked at (map units)
  std::array<double, 3> fixed_up = {0.0, 0.0,
                                    0.0};  // fixed: up direction; zeros = ground normal, else -y
  double framing_percentile = 2.0;  // auto framing ignores this share of map points at each end (%)
  double point_size_px = 4.0;       // static map point diameter (px)
  std::string static_point_color =
      "height";  // height (above the ground plane) | rgb (image colour)
  std::array<double, 2> height_range = {
      0.0, 0.0};                     // heights mapped to the colour scale (map units); equal = auto
  double trajectory_width_px = 3.0;  // camera and object trajectories (px)
  double frustum_size = 0.0;  // keyframe frustum depth (map units); 0 = auto (2% of the scene)
  double voxel_alpha = 0.25;  // opacity of occupied voxels [0, 1]
  double volume_alpha =
      0.30;  // opacity of the current predicted volume; later horizons fade [0, 1]
  bool show_map_points = true;   // static world points
  bool show_keyframes = true;    // keyframes as small frusta
  bool show_trajectory = true;   // camera trajectory (red) and current camera
  bool show_objects = true;      // object points and trajectories
  bool show_particles = true;    // bearing-only tracker particles (green)
  bool show_voxels = true;       // occupied voxels of the static world
  bool show_volumes = true;      // predicted volumes of moving objects (shaded boxes)
  bool show_ground_grid = true;  // grid on the ground plane (when known)
  bool show_legend = true;       // legend and header text

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(width, 16);
    MBSLAM_CHECK_OPTION_LE(width, 8192);
    MBSLAM_CHECK_OPTION_GE(height, 16);
    MBSLAM_CHECK_OPTION_LE(height, 8192);
    MBSLAM_CHECK_OPTION(antialias_samples == 1 || antialias_samples == 2 || antialias_samples == 4);
    for (double c : background_rgb) {
      MBSLAM_CHECK_OPTION_GE(c, 0.0);
      MBSLAM_CHECK_OPTION_LE(c, 1.0);
    }
    MBSLAM_CHECK_OPTION(camera_mode == "follow" || camera_mode == "top_down" ||
                        camera_mode == "fixed");
    MBSLAM_CHECK_OPTION_GT(fov_deg, 1.0);
    MBSLAM_CHECK_OPTION_LT(fov_deg, 170.0);
    MBSLAM_CHECK_OPTION_GE(follow_distance, 0.0);
    MBSLAM_CHECK_OPTION_GE(follow_height, 0.0);
    MBSLAM_CHECK_OPTION_GE(follow_look_ahead, 0.0);
    MBSLAM_CHECK_OPTION(fixed_position != fixed_look_at);
    MBSLAM_CHECK_OPTION_GE(framing_percentile, 0.0);
    MBSLAM_CHECK_OPTION_LT(framing_percentile, 50.0);
    MBSLAM_CHECK_OPTION_GT(point_size_px, 0.0);
    MBSLAM_CHECK_OPTION_LE(point_size_px, 64.0);
    MBSLAM_CHECK_OPTION(static_point_color == "height" || static_point_color == "rgb");
    MBSLAM_CHECK_OPTION_LE(height_range[0], height_range[1]);
    MBSLAM_CHECK_OPTION_GT(trajectory_width_px, 0.0);
    MBSLAM_CHECK_OPTION_LE(trajectory_width_px, 32.0);
    MBSLAM_CHECK_OPTION_GE(frustum_size, 0.0);
    MBSLAM_CHECK_OPTION_GE(voxel_alpha, 0.0);
    MBSLAM_CHECK_OPTION_LE(voxel_alpha, 1.0);
    MBSLAM_CHECK_OPTION_GE(volume_alpha, 0.0);
    MBSLAM_CHECK_OPTION_LE(volume_alpha, 1.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("width", &width, "snapshot width (px)");
    v("height", &height, "snapshot height (px)");
    v("antialias_samples", &antialias_samples, "multisampling: 1 (off), 2 or 4 (count)");
    v("background_rgb", &background_rgb, "background colour, RGB [0, 1]");
    v("camera_mode", &camera_mode, "follow | top_down | fixed");
    v("fov_deg", &fov_deg, "vertical field of view of follow and fixed (deg)");
    v("follow_distance", &follow_distance,
      "follow: eye distance behind the camera (map units); 0 = auto from the data");
    v("follow_height", &follow_height, "follow: eye height above the camera (map units); 0 = auto");
    v("follow_look_ahead", &follow_look_ahead,
      "follow: look-at point ahead of the camera (map units); 0 = auto");
    v("fixed_position", &fixed_position, "fixed: eye position in the world (map units)");
    v("fixed_look_at", &fixed_look_at, "fixed: point looked at in the world (map units)");
    v("fixed_up", &fixed_up, "fixed: up direction; zeros = ground normal, else -y");
    v("framing_percentile", &framing_percentile,
      "auto framing ignores this share of map points at each end (%)");
    v("point_size_px", &point_size_px, "static map point diameter (px)");
    v("static_point_color", &static_point_color,
      "height (above the ground plane) | rgb (image colour)");
    v("height_range", &height_range,
      "heights mapped to the colour scale (map units); equal values = auto");
    v("trajectory_width_px", &trajectory_width_px, "camera and object trajectories (px)");
    v("frustum_size", &frustum_size, "keyframe frustum depth (map units); 0 = auto");
    v("voxel_alpha", &voxel_alpha, "opacity of occupied voxels [0, 1]");
    v("volume_alpha", &volume_alpha,
      "opacity of the current predicted volume; later horizons fade [0, 1]");
    v("show_map_points", &show_map_points, "static world points");
    v("show_keyframes", &show_keyframes, "keyframes as small frusta");
    v("show_trajectory", &show_trajectory, "camera trajectory (red) and current camera");
    v("show_objects", &show_objects, "moving objects' points and trajectories");
    v("show_particles", &show_particles, "bearing-only tracker particles (green)");
    v("show_voxels", &show_voxels, "occupied voxels of the static world");
    v("show_volumes", &show_volumes, "predicted volumes of moving objects");
    v("show_ground_grid", &show_ground_grid, "grid on the ground plane (when known)");
    v("show_legend", &show_legend, "legend and header text");
  }
};

// The camera image with tracks, hulls, flow and epipolar lines (OpenCV drawing).
struct ImageViewOptions {
  double scale = 1.0;              // output size relative to the camera image (ratio)
  int min_width = 640;             // smaller images are enlarged to at least this width (px)
  double feature_radius_px = 3.0;  // track marker radius in the output (px)
  bool show_flow = true;           // flow vectors previous -> current position
  double hull_alpha = 0.35;        // opacity of the hull shading [0, 1]
  std::string epipolar_lines = "degenerate";  // degenerate | moving | off
  double degenerate_epipolar_px =
      2.0;  // "degenerate": moving features within this distance of their epipolar line (px)
  int max_epipolar_lines = 40;  // epipolar lines drawn at most (count)
  bool show_labels = true;      // object ids and speeds near their hulls
  bool show_legend = true;      // legend and header text
  bool dim_image = true;        // darken the camera image so the overlay stands out

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(scale, 0.0);
    MBSLAM_CHECK_OPTION_LE(scale, 8.0);
    MBSLAM_CHECK_OPTION_GE(min_width, 0);
    MBSLAM_CHECK_OPTION_LE(min_width, 8192);
    MBSLAM_CHECK_OPTION_GT(feature_radius_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(hull_alpha, 0.0);
    MBSLAM_CHECK_OPTION_LE(hull_alpha, 1.0);
    MBSLAM_CHECK_OPTION(epipolar_lines == "degenerate" || epipolar_lines == "moving" ||
                        epipolar_lines == "off");
    MBSLAM_CHECK_OPTION_GE(degenerate_epipolar_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_epipolar_lines, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("scale", &scale, "output size relative to the camera image (ratio)");
    v("min_width", &min_width, "smaller outputs are enlarged to at least this width (px)");
    v("feature_radius_px", &feature_radius_px, "track marker radius in the output (px)");
    v("show_flow", &show_flow, "flow vectors previous -> current position");
    v("hull_alpha", &hull_alpha, "opacity of the hull shading [0, 1]");
    v("epipolar_lines", &epipolar_lines,
      "degenerate (moving features on their epipolar line) | moving (all moving features) | off");
    v("degenerate_epipolar_px", &degenerate_epipolar_px,
      "degenerate: moving features within this distance of the static epipolar line (px)");
    v("max_epipolar_lines", &max_epipolar_lines, "epipolar lines drawn at most (count)");
    v("show_labels", &show_labels, "object ids and speeds near their hulls");
    v("show_legend", &show_legend, "legend and header text");
    v("dim_image", &dim_image, "darken the camera image so the overlay stands out");
  }
};

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_RENDER_OPTIONS_H_
