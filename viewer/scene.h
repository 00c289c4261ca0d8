#ifndef MBSLAM_VIEWER_SCENE_H_
#define MBSLAM_VIEWER_SCENE_H_

// What the viewer draws, as plain structs (no LCM): the LCM adapter converts each
// PERCEPTION_* / CAMERA_IMAGE message into one of these and hands it to SceneState,
// which keeps the latest map, objects and occupancy, the trajectories, and small
// buffers of tracks, objects and images so that an image view can be put together
// from messages of the same utime.
//
// Frames: everything 3D is in the static world frame of the map (the SLAM frame of the
// first keyframe's camera: x right, y down, z forward, unless a ground plane says where
// "up" is). Poses are world_from_cam. Units are metres when `metric`, else map units.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "viewer/render_options.h"

namespace mbslam {
namespace viewer {

// Same values as camera_pose_t.TRACKING_* (the adapter checks it at compile time).
enum class TrackingState : int8_t {
  kNotInitialized = 0,
  kInitializing = 1,
  kOk = 2,
  kLost = 3,
  kRelocalized = 4,
};

// True when the pose of that state is an estimate (not the identity placeholder).
bool HasPose(TrackingState state);

struct Pose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               // translation (units)
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // rotation
};

struct CameraPoseSample {
  int64_t utime = 0;  // µs
  Pose world_from_cam;
  TrackingState tracking_state = TrackingState::kNotInitialized;
  bool metric = false;
};

struct KeyframeData {
  int64_t id = 0;
  Pose world_from_cam;
};

struct MapData {
  int64_t utime = 0;  // µs
  bool metric = false;
  std::vector<Eigen::Vector3f> points;         // world frame (units)
  std::vector<std::array<uint8_t, 3>> colors;  // R, G, B per point, or empty
  std::vector<KeyframeData> keyframes;
  std::optional<Eigen::Vector4d> ground_plane;  // n . x + d = 0, |n| = 1, n up
};

// An oriented box that contains a moving object (predicted_volume_t).
struct OrientedBox {
  int64_t utime = 0;                                 // time the box is for (µs)
  int64_t horizon_us = 0;                            // utime minus the time of the estimate (µs)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // world (units)
  Eigen::Quaterniond world_from_box = Eigen::Quaterniond::Identity();
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();  // units
  double probability = 0.0;                               // [0, 1]
};

// Same values as object_t.STATE_*.
enum class ObjectState : int8_t { kDetected = 0, kTracked = 1, kReconstructed = 2 };

struct ObjectData {
  int id = 0;  // > 0
  ObjectState state = ObjectState::kDetected;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();         // world (units)
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();  // world (units/s)
  std::vector<Eigen::Vector3f> particles;                     // world (units)
  std::vector<Eigen::Vector3f> points;                        // world (units)
  std::vector<OrientedBox> volumes;                           // increasing horizon
};

struct ObjectsData {
  int64_t utime = 0;  // µs
  bool metric = false;
  std::vector<ObjectData> objects;
};

// An occupancy map as it arrives (OcTree::writeBinary bytes); decoded when drawn.
struct EncodedOccupancy {
  int64_t utime = 0;  // µs
  bool metric = false;
  double resolution = 0.0;  // voxel edge (units)
  std::vector<uint8_t> data;
};

struct Voxel {
  Eigen::Vector3f center = Eigen::Vector3f::Zero();  // world (units)
  float size = 0.0f;                                 // edge length (units)
};

struct OccupancyData {
  int64_t utime = 0;          // µs
  double resolution = 0.0;    // units
  std::vector<Voxel> voxels;  // occupied leaves, at most SceneOptions::max_voxels
  int64_t num_occupied = 0;   // occupied leaves in the tree (count)
};

struct TrackFeature {
  int64_t id = 0;
  float u = 0.0f, v = 0.0f;            // current position (px)
  float prev_u = 0.0f, prev_v = 0.0f;  // previous position (px), NaN if new
  int body_id = -1;                    // 0 static, > 0 object, -1 unassigned
  float p_static = 0.5f;               // [0, 1]
  float epipolar_px = 0.0f;            // distance to the static epipolar line (px), NaN if unknown
  bool occluded = false;
  bool is_new = false;
};

struct ImageHull {
  int body_id = 0;
  std::vector<Eigen::Vector2f> points;  // px, counter-clockwise
};

struct TracksData {
  int64_t utime = 0;  // µs
  int64_t frame_seq = 0;
  int width = 0, height = 0;                          // px
  Eigen::Vector3d epipole = Eigen::Vector3d::Zero();  // homogeneous (px); zeros = unknown
  std::vector<TrackFeature> tracks;
  std::vector<ImageHull> hulls;
};

// Same values as image_t.ENCODING_*.
enum class ImageEncoding : int8_t { kGray8 = 0, kRgb8 = 1, kBgr8 = 2, kJpeg = 3, kPng = 4 };

struct EncodedImage {
  int64_t utime = 0;  // µs
  int width = 0, height = 0, row_stride = 0;
  ImageEncoding encoding = ImageEncoding::kGray8;
  std::vector<uint8_t> data;
};

// What an image view is made of: the newest tracks that have their image, or the
// newest image alone, or the newest tracks alone (pointers into SceneState; null when
// absent).
struct ImageFrame {
  const TracksData* tracks = nullptr;
  const EncodedImage* image = nullptr;
  const ObjectsData* objects = nullptr;  // same utime as the tracks when buffered, else the newest
  int64_t utime = 0;
};

class SceneState {
 public:
  explicit SceneState(const SceneOptions& options = SceneOptions());

  void AddCameraPose(const CameraPoseSample& pose);
  void SetMap(MapData map);
  void SetObjects(ObjectsData objects);
  void SetOccupancy(EncodedOccupancy occupancy);
  void AddTracks(TracksData tracks);
  void AddImage(EncodedImage image);

  // Forgets everything (time went backwards: a new run or a looped log).
  void Clear();

  // Newest utime of any message added (µs); 0 before the first.
  int64_t latest_utime() const { return latest_utime_; }
  bool empty() const { return latest_utime_ == 0; }
  // True when the newest pose, map or objects said metres.
  bool metric() const { return metric_; }

  const std::vector<CameraPoseSample>& camera_trajectory() const { return trajectory_; }
  const std::optional<CameraPoseSample>& current_camera() const { return current_camera_; }
  const MapData& map() const { return map_; }
  const ObjectsData& objects() const { return objects_.empty() ? empty_objects_ : objects_.back(); }
  const std::map<int, std::vector<Eigen::Vector3d>>& object_trajectories() const {
    return object_trajectories_;
  }
  // The decoded occupancy (decoded on first use after it changed). A tree that does not
  // decode gives an empty occupancy and counts in occupancy_decode_errors().
  const OccupancyData& occupancy() const;
  int64_t occupancy_decode_errors() const { return occupancy_decode_errors_; }
  // Image size from the newest tracks (px); 0 when unknown.
  int image_width() const { return image_width_; }
  int image_height() const { return image_height_; }

  ImageFrame LatestImageFrame() const;

  // Counters: poses or messages ignored because their time went backwards and the
  // state was reset (count).
  int64_t resets() const { return resets_; }

 private:
  void Touch(int64_t utime);
  void ResetTrajectoriesOnUnitChange(bool metric);

  SceneOptions options_;
  int64_t latest_utime_ = 0;
  bool metric_ = false;
  bool have_unit_ = false;
  std::vector<CameraPoseSample> trajectory_;
  std::optional<CameraPoseSample> current_camera_;
  MapData map_;
  std::deque<ObjectsData> objects_;  // newest last
  ObjectsData empty_objects_;
  std::map<int, std::vector<Eigen::Vector3d>> object_trajectories_;
  std::map<int, int64_t> object_last_seen_;
  EncodedOccupancy occupancy_encoded_;
  mutable OccupancyData occupancy_;
  mutable bool occupancy_dirty_ = false;
  mutable int64_t occupancy_decode_errors_ = 0;
  std::deque<TracksData> tracks_;    // newest last
  std::deque<EncodedImage> images_;  // newest last
  int image_width_ = 0, image_height_ = 0;
  int64_t resets_ = 0;
};

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_SCENE_H_
