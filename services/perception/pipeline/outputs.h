#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_OUTPUTS_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_OUTPUTS_H_

// What the pipeline produces, as plain structs. lcm_adapters/ turns them into the
// PERCEPTION_* messages; tests and tools read them directly.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "services/perception/geometry/rigid3.h"

namespace mbslam {

enum class TrackingState { kNotInitialized = 0, kInitializing = 1, kOk = 2, kLost = 3, kRelocalized = 4 };
enum class ScaleState { kUpToScale = 0, kMetric = 1 };

const char* TrackingStateName(TrackingState state);

struct CameraPoseOutput {
  int64_t utime = 0;
  int64_t frame_seq = 0;
  Rigid3d world_from_cam;
  Matrix6d covariance = Matrix6d::Zero();  // left perturbation [t; r] of world_from_cam
  TrackingState tracking_state = TrackingState::kNotInitialized;
  ScaleState scale_state = ScaleState::kUpToScale;
  double scale_to_metric = 0.0;  // metres per map unit, 0 if unknown
  int num_inliers = 0;
  int num_keyframes = 0;
};

struct TrackOutput {
  int64_t id = 0;
  Eigen::Vector2f uv = Eigen::Vector2f::Zero();       // px
  Eigen::Vector2f prev_uv = Eigen::Vector2f::Constant(NAN);  // px, NaN if new
  int age = 0;
  int body_id = -1;      // 0 static, > 0 object, -1 unassigned
  float p_static = 0.5f;
  float epipolar_px = NAN;
  float fvb = NAN;
  bool has_3d = false;
  bool occluded = false;
  bool is_new = false;
};

struct HullOutput {
  int body_id = 0;
  std::vector<Eigen::Vector2f> points;  // px, counter-clockwise
};

struct PredictedVolumeOutput {
  int64_t utime = 0;
  int64_t horizon_us = 0;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d half_extent = Eigen::Vector3d::Zero();
  double probability = 0.0;
};

enum class ObjectState { kDetected = 0, kTracked = 1, kReconstructed = 2 };
enum class ObjectClass { kUnknown = 0, kPerson = 1 };

struct ObjectOutput {
  int id = 0;
  ObjectState state = ObjectState::kDetected;
  ObjectClass object_class = ObjectClass::kUnknown;
  int64_t first_seen_utime = 0;
  int num_tracks = 0;
  Rigid3d world_from_object;
  Matrix6d pose_covariance = Matrix6d::Zero();
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();
  Matrix6d velocity_covariance = Matrix6d::Zero();
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  double depth = 0.0;
  double depth_sigma = 0.0;
  double relative_scale = 0.0;
  double relative_scale_sigma = 0.0;
  HullOutput hull;
  int num_particles = 0;
  double effective_sample_size = 0.0;
  std::vector<Eigen::Vector3f> particle_samples;
  std::vector<Eigen::Vector3f> points;
  std::vector<PredictedVolumeOutput> volumes;
};

// A moving object's own reconstruction (its SLAM) in one image, in the object's map
// frame and units: for the trajectory files and evaluation.
struct ObjectReconstructionOutput {
  int object_id = 0;                    // persistent object id (as in ObjectOutput)
  int64_t map_id = 0;                   // a new map (new scale) at every initialisation
  Rigid3d cam_from_obj;                 // object map units
  int num_points = 0;
  bool points_included = false;         // `points` is the whole map (at its keyframes, periodically)
  std::vector<Eigen::Vector3f> points;  // object frame (object map units)
};

struct KeyframeOutput {
  int64_t id = 0;
  int64_t utime = 0;
  Rigid3d world_from_cam;
  int num_observations = 0;
};

struct MapOutput {
  int64_t utime = 0;
  ScaleState scale_state = ScaleState::kUpToScale;
  std::vector<int64_t> point_ids;
  std::vector<Eigen::Vector3f> points;
  std::vector<std::array<uint8_t, 3>> colors;
  std::vector<KeyframeOutput> keyframes;
  Eigen::Vector4d ground_plane = Eigen::Vector4d::Zero();
};

struct OccupancyOutput {
  int64_t utime = 0;
  ScaleState scale_state = ScaleState::kUpToScale;
  double resolution = 0.0;
  int num_occupied = 0;
  int64_t memory_bytes = 0;   // the probabilistic tree in memory, estimated (bytes)
  std::string octree_binary;  // octomap::OcTree::writeBinary stream
};

// Everything produced for one image. Optional parts are published only when present
// (the map and occupancy at a lower rate than the pose).
struct FrameResult {
  int64_t utime = 0;
  int64_t frame_seq = 0;
  int width = 0;
  int height = 0;
  int64_t receive_wall_utime = 0;
  CameraPoseOutput camera_pose;
  // (utime, world_from_cam) of earlier images that had no pose, recovered when a map was
  // confirmed with this image or tracking came back on it after a loss
  // (SlamOptions::backfill_max_frames): for the trajectory
  // files only, the live pose stream having passed them.
  std::vector<std::pair<int64_t, Rigid3d>> backfilled_camera_poses;
  Eigen::Vector3d epipole = Eigen::Vector3d::Zero();
  std::vector<TrackOutput> tracks;
  std::vector<HullOutput> hulls;
  std::vector<ObjectOutput> objects;
  std::vector<ObjectReconstructionOutput> object_reconstructions;
  std::optional<MapOutput> map;
  std::optional<OccupancyOutput> occupancy;
  // The world frame's units changed in this image (e.g. to metres once odometry fixed
  // the scale): earlier world positions are to be multiplied by this factor.
  std::optional<double> world_rescaled_by;
};

// Receives the pipeline's results on the processing thread, in frame order.
class OutputSink {
 public:
  virtual ~OutputSink() = default;
  virtual void OnFrameResult(const FrameResult& result) = 0;
  // Once, after the last image: the camera trajectory as the map finally has it
  // ((utime, world_from_cam), oldest first; images of a dropped map, or whose keyframe was
  // culled, with that keyframe's last pose; images beyond the SLAM's bound are absent).
  // What a sink does with it is its own affair.
  virtual void OnAdjustedCameraTrajectory(const std::vector<std::pair<int64_t, Rigid3d>>& world_from_cam) {
    (void)world_from_cam;
  }
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_OUTPUTS_H_
