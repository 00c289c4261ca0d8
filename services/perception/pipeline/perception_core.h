#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_PERCEPTION_CORE_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_PERCEPTION_CORE_H_

// The coupled per-frame chain of the thesis (fig. 1.4): tracking -> segmentation ->
// SLAM -> object tracking -> fusion -> occupancy, with their feedback paths. Runs on
// the pipeline's processing thread; knows nothing of LCM.

#include <array>
#include <atomic>
#include <cmath>
#include <future>
#include <map>
#include <memory>
#include <optional>
#include <unordered_set>
#include <utility>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "common/config/options.h"
#include "services/perception/geometry/pose_buffer.h"
#include "services/perception/objects/ground_plane.h"
#include "services/perception/objects/object_tracking.h"
#include "services/perception/occupancy/occupancy_map.h"
#include "services/perception/pipeline/counters.h"
#include "services/perception/pipeline/frame_processor.h"
#include "services/perception/pipeline/stage_timers.h"
#include "services/perception/segmentation/motion_segmenter.h"
#include "services/perception/segmentation/person_detector.h"
#include "services/perception/slam/object_reconstruction.h"
#include "services/perception/slam/slam_system.h"
#include "services/perception/tracking/feature_tracker.h"

namespace mbslam {

struct PreprocessOptions {
  int pyramid_levels = 4;  // image pyramid levels for tracking, level 0 = full resolution (count)
  int max_odometry_samples = 20000;  // odometry samples kept for interpolation (count)
  int64_t max_odometry_gap_us = 500000;  // largest odometry spacing to interpolate across (µs)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(pyramid_levels, 1);
    MBSLAM_CHECK_OPTION_LE(pyramid_levels, 8);
    MBSLAM_CHECK_OPTION_GT(max_odometry_samples, 1);
    MBSLAM_CHECK_OPTION_GT(max_odometry_gap_us, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("pyramid_levels", &pyramid_levels, "image pyramid levels, 0 = full resolution (count)");
    v("max_odometry_samples", &max_odometry_samples, "odometry samples kept (count)");
    v("max_odometry_gap_us", &max_odometry_gap_us, "largest odometry spacing to interpolate (us)");
  }
};

// Ego-motion from wheel odometry (thesis sec. 3.8).
struct OdometryOptions {
  bool use_for_ego_motion = true;   // camera motion from odometry when it covers both images
  std::array<double, 3> base_from_cam_translation{{0.0, 0.0, 0.0}};  // camera origin in the robot base frame (m)
  std::array<double, 4> base_from_cam_rotation{{0.5, -0.5, 0.5, -0.5}};  // [w, x, y, z]; default: camera z forward = base x, camera x right = base -y
  double sigma_translation_per_m = 0.02;   // odometry translation noise per metre travelled (m/m)
  double sigma_rotation_per_rad = 0.02;    // odometry rotation noise per radian turned (rad/rad)
  double sigma_translation_floor_m = 0.002;  // translation noise floor per image pair (m)
  double sigma_rotation_floor_rad = 0.002;   // rotation noise floor per image pair (rad)
  double min_depth_m = 0.3;         // nearest plausible static point (flow vector bound) (m)
  double max_depth_m = 0.0;         // farthest plausible static point; 0 = unbounded (m)
  int64_t max_extrapolation_us = 60000;  // an image newer than the last odometry by at most this is extrapolated (µs)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(sigma_translation_per_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(sigma_rotation_per_rad, 0.0);
    MBSLAM_CHECK_OPTION_GT(sigma_translation_floor_m, 0.0);
    MBSLAM_CHECK_OPTION_GT(sigma_rotation_floor_rad, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_depth_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_depth_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_extrapolation_us, 0);
    const double n = std::sqrt(base_from_cam_rotation[0] * base_from_cam_rotation[0] +
                               base_from_cam_rotation[1] * base_from_cam_rotation[1] +
                               base_from_cam_rotation[2] * base_from_cam_rotation[2] +
                               base_from_cam_rotation[3] * base_from_cam_rotation[3]);
    MBSLAM_CHECK_OPTION(std::abs(n - 1.0) < 1e-6);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("use_for_ego_motion", &use_for_ego_motion, "camera motion from odometry when available");
    v("base_from_cam_translation", &base_from_cam_translation, "camera origin in the base frame (m)");
    v("base_from_cam_rotation", &base_from_cam_rotation, "base_from_cam rotation [w, x, y, z]");
    v("sigma_translation_per_m", &sigma_translation_per_m, "translation noise per metre (m/m)");
    v("sigma_rotation_per_rad", &sigma_rotation_per_rad, "rotation noise per radian (rad/rad)");
    v("sigma_translation_floor_m", &sigma_translation_floor_m, "translation noise floor (m)");
    v("sigma_rotation_floor_rad", &sigma_rotation_floor_rad, "rotation noise floor (rad)");
    v("min_depth_m", &min_depth_m, "nearest plausible static point (m)");
    v("max_depth_m", &max_depth_m, "farthest plausible static point, 0 = unbounded (m)");
    v("max_extrapolation_us", &max_extrapolation_us, "extrapolate odometry at most this far past its last sample (us)");
  }
};

// The sections of the perception options the core uses.
struct CoreOptions {
  PreprocessOptions preprocess;
  TrackerOptions tracking;
  SegmentationOptions segmentation;
  PersonDetectorOptions person;
  OdometryOptions odometry;
  SlamOptions slam;
  GroundPlaneOptions ground;
  OccupancyMapOptions occupancy;
  bool occupancy_enabled = true;      // build and publish the static-world occupancy map
  int64_t occupancy_publish_period_us = 1000000;  // PERCEPTION_OCCUPANCY at most this often, at keyframes (µs)
  ObjectTrackingOptions objects;
  ObjectReconstructionOptions object_slam;
  int map_publish_every_frames = 15;  // PERCEPTION_MAP at most this often, and at every keyframe
  // Person checks launched with one image are collected with the next: waiting for them
  // (lockstep: the same result every run) or, live, taking them when done and launching
  // no new ones meanwhile (the niced job never stalls an image).
  bool wait_for_person_checks = true;
};

class PerceptionCore : public FrameProcessor {
 public:
  PerceptionCore(const CoreOptions& options, Counters* counters, StageTimers* timers);

  void OnOdometry(const OdometrySample& odometry) override;
  FrameResult ProcessFrame(const ImageFrame& frame) override;

  const PoseBuffer& odometry() const { return odometry_; }
  const SlamSystem& slam() const { return slam_; }
  // Asks for a global bundle adjustment of the static map, taken up by the next image
  // (SlamSystem::RequestGlobalBundleAdjustment). Thread-safe: the LCM thread calls it on
  // a SNAPSHOT_REQUEST with WHAT_GLOBAL_BA.
  void RequestGlobalBundleAdjustment() { global_ba_request_.store(true); }
  size_t num_object_records() const { return object_records_.size(); }
  void Finish() override {
    slam_.Flush();
    object_reconstruction_->Flush();
  }
  std::vector<std::pair<int64_t, Rigid3d>> AdjustedCameraTrajectory() const override;

 private:
  // A relocalised image's match lands this close to a track the tracker already has (px).
  static constexpr float kRelocalizedTrackRadiusPx = 2.0f;
  // The active track nearest to uv within radius_px that holds no map point, is not
  // labelled moving and was not released from a point as an outlier, or -1.
  int64_t UnmappedTrackAt(const Eigen::Vector2f& uv, float radius_px) const;
  std::optional<RelativeMotion> OdometryMotion(int64_t ref_frame, int64_t cur_frame) const;
  std::optional<Rigid3d> OdometryCameraPose(int64_t utime) const;
  void FillCameraPose(const SlamPose& pose, CameraPoseOutput* out) const;
  void UpdateGroundPlane();
  // Rays from the new keyframe to its new static points, and interpolated rays inside the
  // image triangulation of all static points it sees (not across `moving_hulls_xy`, the
  // moving objects' outlines in normalised coordinates); the tree re-published when it
  // changed.
  // Adds the memory-bound crops of the occupancy map not counted yet to the counters.
  void CountOccupancyCrops();
  void UpdateOccupancy(const SlamMapUpdate& update, int64_t utime, double focal_px,
                       const std::vector<std::vector<Eigen::Vector2d>>& moving_hulls_xy, FrameResult* result);
  // SLAM's depth bound of a track, capped by where its ray meets the ground.
  DepthBound DepthBoundFor(int64_t track_id, const Eigen::Vector2d& xy, int64_t frame) const;
  // Affine patch warps once this image's pose is known: static tracks with a map point are
  // re-aligned on their reference appearance (from a keyframe) warped into this image
  // through the local surface plane (the ground's when the point lies on it, else facing
  // the reference camera); corrected positions replace the observations in `slam_frame`.
  void AlignOnWarpedReferences(const Rigid3d& cam_from_world, const CameraIntrinsics& intrinsics,
                               SlamFrame* slam_frame);
  // At a new keyframe: static map tracks without a usable reference take this image.
  void SetWarpReferences();
  MapOutput BuildMapOutput(int64_t utime) const;
  void FillObjectEstimate(const TrackedObject& tracked, ObjectOutput* out) const;
  void Reset();
  void CollectPersonChecks();  // results of the previous image's person checks into object_records_

  const CoreOptions options_;
  Counters* counters_;
  TimingStats* preprocess_timer_;
  TimingStats* tracking_timer_;
  TimingStats* segmentation_timer_;
  TimingStats* slam_timer_;
  TimingStats* mapping_timer_;
  TimingStats* occupancy_timer_;
  TimingStats* objects_timer_;
  TimingStats* person_timer_;   // person checks (part of no other stage)
  TimingStats* ba_timer_;       // bundle adjustment runs (solver time, back-end thread)
  TimingStats* global_ba_timer_;  // global bundle adjustments asked for (solver time)
  TimingStats* outputs_timer_;  // map / track messages built for the sinks
  PoseBuffer odometry_;
  Rigid3d base_from_cam_;
  FeatureTracker tracker_;
  MotionSegmenter segmenter_;
  PersonDetector person_detector_;
  SlamSystem slam_;
  std::optional<GroundPlane> ground_;
  ObjectTracking object_tracking_;
  std::unique_ptr<ObjectReconstruction> object_reconstruction_;
  TimingStats* object_slam_timer_;
  TimingStats* warp_timer_;  // affine-warp re-alignment of tracks (after the pose)
  // Tracks whose warp left the range where their reference is used well: re-referenced
  // at the next keyframe.
  std::unordered_set<int64_t> rereference_tracks_;
  std::unique_ptr<OccupancyMap> occupancy_;  // static world only (sec. 6.3); null until rays arrive
  int64_t occupancy_crops_counted_ = 0;    // occupancy_->crops() already on the counters
  int64_t occupancy_dropped_counted_ = 0;  // occupancy_->occupied_voxels_dropped() already counted
  std::optional<int64_t> last_occupancy_publish_utime_;
  int64_t last_map_publish_frame_ = -1000000;
  std::vector<cv::Mat> pyramid_;
  std::map<int64_t, int64_t> frame_utime_;   // frame index -> image time (recent frames)
  std::vector<TrackingHints::Hull> occluders_;  // moving objects' hulls predicted for the next image
  // What is kept per reported object id, forgotten objects.forget_after_us after the
  // object was last reported (ids are never reused; a long run meets ever new ones).
  struct ObjectRecord {
    int64_t first_utime = 0;             // first reported (first_seen_utime)
    int64_t last_utime = 0;              // last reported
    std::optional<int64_t> person_checked_frame;  // frame of the last person check
    bool is_person = false;
    int64_t sfm_map_id = 0;                   // the object's reconstruction whose points are below
    std::vector<Eigen::Vector3d> sfm_points;  // its points (object frame, object units)
  };
  ObjectRecord& RecordOf(int id, int64_t utime);
  void ForgetGoneObjects(int64_t utime);
  std::map<int, ObjectRecord> object_records_;
  int64_t segment_links_forgotten_ = 0;  // object_tracking_'s count already reported
  // Person checks of the previous image, running on another thread (object id, found).
  std::future<std::vector<std::pair<int, bool>>> person_job_;
  int64_t frame_index_ = -1;
  int64_t ba_runs_seen_ = 0;
  std::atomic<bool> global_ba_request_{false};
  int64_t requested_ba_runs_seen_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_PERCEPTION_CORE_H_
