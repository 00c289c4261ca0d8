#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_MAP_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_MAP_H_

// One body's keyframe map (thesis ch. 4): keyframes with their camera poses and the
// track observations they hold, and triangulated points. Poses are cam_from_world;
// "world" is the body's own frame (the static world, or a moving object's frame).

#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/tracking/orb_features.h"

namespace mbslam {

// A rotation that the mapped body keeps nearly constant relative to another frame, given
// per image: for a moving object's SLAM, the static world SLAM's camera rotation
// (cam_from_world of the world map). A body that does not turn in that frame has
// R_cam_b_from_body * R_cam_a_from_body^T = R_cam_b_from_ref * R_cam_a_from_ref^T between any
// two images a, b; priors are compared only within one reference (ref_id: a new world map
// is a new reference).
struct CameraRotationPrior {
  Eigen::Quaterniond cam_from_ref = Eigen::Quaterniond::Identity();
  int64_t ref_id = 0;
};

struct Observation {
  int64_t keyframe_id = 0;
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // normalised undistorted coordinates
};

struct MapPoint {
  int64_t id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // point_in_world
  int64_t track_id = -1;            // the feature track currently observing it, -1 if none
  std::vector<Observation> observations;
  int64_t created_frame = 0;
  int64_t last_seen_frame = 0;
  int times_visible = 0;            // frames it was predicted in view
  int times_found = 0;              // frames it was matched
  bool occluded = false;            // behind a moving object (sec. 4.3): kept, not matched
  int64_t released_frame = -1;      // image at which its last track was released (moving, or drifted off it); -1 = never
  uint8_t gray = 128;               // intensity at creation (for display)
  cv::Mat patch;                    // appearance at the last observation (guided matching)
  // ORB descriptor at its latest keyframe observation (relocalisation), when it has one.
  bool has_descriptor = false;
  OrbDescriptor descriptor;
};

struct Keyframe {
  int64_t id = 0;
  int64_t frame_index = 0;
  int64_t utime = 0;
  Rigid3d cam_from_world;
  bool fixed = false;               // gauge: never moved by bundle adjustment
  std::unordered_map<int64_t, Eigen::Vector2d> track_xy;  // every static track seen here
  std::unordered_map<int64_t, Eigen::Vector2d> track_uv;  // the same in pixels
  std::vector<int64_t> point_ids;   // points observed in this keyframe
  bool has_odometry = false;
  Rigid3d odom_from_cam;            // from interpolated odometry, when available (metric)
  std::optional<CameraRotationPrior> rotation_prior;  // when the images carry one (object SLAMs)
};

class Map {
 public:
  int64_t AddKeyframe(Keyframe keyframe);
  int64_t AddPoint(MapPoint point);
  void AddObservation(int64_t point_id, int64_t keyframe_id, const Eigen::Vector2d& xy);
  void RemovePoint(int64_t point_id);
  // Points held by fewer than two keyframes (culling took the others) that no track
  // still matches: without a track (released) or not matched since `seen_before_frame`
  // (the track died or stays lost). Keyframe culling spares such points while a track
  // holds them; nothing else would ever remove them once their keyframes are gone.
  // Returns how many were removed.
  int RemoveStalePoints(int64_t seen_before_frame);
  void Clear();

  MapPoint* point(int64_t id);
  const MapPoint* point(int64_t id) const;
  Keyframe* keyframe(int64_t id);
  const Keyframe* keyframe(int64_t id) const;

  const std::map<int64_t, Keyframe>& keyframes() const { return keyframes_; }
  std::map<int64_t, Keyframe>& keyframes() { return keyframes_; }
  const std::unordered_map<int64_t, MapPoint>& points() const { return points_; }
  std::unordered_map<int64_t, MapPoint>& points() { return points_; }
  // The map point a track observes, or -1.
  int64_t PointOfTrack(int64_t track_id) const;
  void AssociateTrack(int64_t point_id, int64_t track_id);
  void ReleaseTrack(int64_t track_id);

  const Keyframe* LastKeyframe() const;
  size_t num_keyframes() const { return keyframes_.size(); }
  size_t num_points() const { return points_.size(); }
  // Points with an ORB descriptor (what relocalisation can match).
  size_t num_described_points() const;

  // Multiplies every position by s (gauge change, e.g. to metric units).
  void Rescale(double s);

  // Text file: keyframes (id, frame, utime, pose) and points (id, xyz, grey level,
  // observations, ORB descriptor as 64 hex digits or "-", guided matching patch as its
  // side and hex bytes or 0). Load reads this (version 2)
  // and version 1 (without descriptors); it refuses malformed or non-finite numbers and
  // observations of missing keyframes, and leaves the map as it was then.
  Status Save(const std::string& path) const;
  Status Load(const std::string& path);

 private:
  std::map<int64_t, Keyframe> keyframes_;
  std::unordered_map<int64_t, MapPoint> points_;
  std::unordered_map<int64_t, int64_t> point_of_track_;
  int64_t next_keyframe_id_ = 0;
  int64_t next_point_id_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_MAP_H_
