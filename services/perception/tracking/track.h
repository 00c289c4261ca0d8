#ifndef MBSLAM_SERVICES_PERCEPTION_TRACKING_TRACK_H_
#define MBSLAM_SERVICES_PERCEPTION_TRACKING_TRACK_H_

#include <cmath>
#include <cstdint>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace mbslam {

enum class TrackStatus {
  kActive,    // observed in the latest image
  kOccluded,  // predicted behind a moving object's hull: kept, not matched
};

// A feature track in the image. Positions are distorted pixel coordinates.
struct Track {
  int64_t id = 0;
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();               // latest position (px)
  Eigen::Vector2f prev_uv = Eigen::Vector2f::Constant(NAN);   // position in the previous image (px)
  Eigen::Vector2f velocity = Eigen::Vector2f::Zero();         // smoothed image velocity (px / frame)
  int age = 1;                     // images the track was observed in
  int64_t first_frame = 0;         // frame index of the first observation
  int64_t last_seen_frame = 0;     // frame index of the latest observation
  TrackStatus status = TrackStatus::kActive;
  int occluded_frames = 0;         // consecutive frames spent occluded
  float match_error = 0.0f;        // forward-backward error of the last match (px)
  cv::Mat patch;                   // template at the last observation (ZSSD re-detection)
  cv::Mat anchor;                  // template at the first observation (drift check)
  // Reference appearance for affine patch warps (FeatureTracker::SetWarpReferences): a
  // larger float patch, its position, and the caller's key of that view (the perception
  // loop uses its keyframe's image index; -1 none).
  cv::Mat warp_reference;
  Eigen::Vector2f warp_reference_uv = Eigen::Vector2f::Constant(NAN);
  int64_t warp_reference_key = -1;
  // Set by segmentation / SLAM (fed back to the tracker):
  int body_id = -1;                // 0 static world, > 0 object, -1 unassigned
  float p_static = 0.5f;           // P(static w.r.t. the static world)
  bool has_3d = false;             // has a map point in its body's map
  bool is_new = true;              // created in the latest image
  bool on_object = false;          // added inside a moving hull, above max_features (object_features), until labelled static

  bool active() const { return status == TrackStatus::kActive; }
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_TRACKING_TRACK_H_
