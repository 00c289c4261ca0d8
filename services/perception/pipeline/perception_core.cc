#include "services/perception/pipeline/perception_core.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <set>
#include <utility>

#include <opencv2/video/tracking.hpp>

#include "common/util/logging.h"
#include "services/perception/geometry/patch_warp.h"
#include "services/perception/geometry/polygon.h"

namespace mbslam {

PerceptionCore::PerceptionCore(const CoreOptions& options, Counters* counters, StageTimers* timers)
    : options_(options),
      counters_(counters),
      preprocess_timer_(timers->Get("preprocess")),
      tracking_timer_(timers->Get("tracking")),
      segmentation_timer_(timers->Get("segmentation")),
      slam_timer_(timers->Get("slam_tracking")),
      mapping_timer_(timers->Get("slam_mapping")),
      occupancy_timer_(timers->Get("occupancy")),
      objects_timer_(timers->Get("objects")),
      person_timer_(timers->Get("person")),
      ba_timer_(timers->Get("local_ba")),
      global_ba_timer_(timers->Get("global_ba")),
      outputs_timer_(timers->Get("outputs")),
      odometry_(options.preprocess.max_odometry_gap_us,
                static_cast<size_t>(options.preprocess.max_odometry_samples)),
      tracker_(options.tracking),
      segmenter_(options.segmentation),
      person_detector_(options.person),
      slam_(options.slam),
      object_tracking_(options.objects),
      object_reconstruction_(
          std::make_unique<ObjectReconstruction>(options.object_slam, options.slam)),
      object_slam_timer_(timers->Get("object_slam")),
      warp_timer_(timers->Get("warp_alignment")) {
  const auto& q = options.odometry.base_from_cam_rotation;
  const auto& t = options.odometry.base_from_cam_translation;
  base_from_cam_ = Rigid3d(Eigen::Quaterniond(q[0], q[1], q[2], q[3]), Eigen::Vector3d(t[0], t[1], t[2]));
}

int64_t PerceptionCore::UnmappedTrackAt(const Eigen::Vector2f& uv, float radius_px) const {
  int64_t best = -1;
  float best_d2 = radius_px * radius_px;
  for (const Track& t : tracker_.tracks()) {
    if (!t.active() || t.body_id > 0 || slam_.HasPoint(t.id) || slam_.IsReleasedTrack(t.id))
      continue;
    const float d2 = (t.uv - uv).squaredNorm();
    if (d2 <= best_d2) {
      best_d2 = d2;
      best = t.id;
    }
  }
  return best;
}

std::vector<std::pair<int64_t, Rigid3d>> PerceptionCore::AdjustedCameraTrajectory() const {
  std::vector<std::pair<int64_t, Rigid3d>> out = slam_.AdjustedTrajectory();
  for (auto& [utime, pose] : out) pose = pose.Inverse();  // world_from_cam
  return out;
}

void PerceptionCore::Reset() {
  slam_.Reset();
  slam_.ForgetLostMaps();  // starting over: the kept maps belong to the timeline left behind
  rereference_tracks_.clear();
  ground_.reset();
  occupancy_.reset();
  last_occupancy_publish_utime_.reset();
  object_tracking_.Reset();
  object_reconstruction_ = std::make_unique<ObjectReconstruction>(options_.object_slam, options_.slam);
  tracker_.Reset();
  segmenter_.Reset();
  odometry_.Clear();
  frame_utime_.clear();
  occluders_.clear();
  if (person_job_.valid()) person_job_.wait();
  person_job_ = {};
  object_records_.clear();
}

PerceptionCore::ObjectRecord& PerceptionCore::RecordOf(int id, int64_t utime) {
  auto [it, inserted] = object_records_.try_emplace(id);
  if (inserted) it->second.first_utime = utime;
  it->second.last_utime = std::max(it->second.last_utime, utime);
  return it->second;
}

void PerceptionCore::ForgetGoneObjects(int64_t utime) {
  int64_t forgotten = 0;
  for (auto it = object_records_.begin(); it != object_records_.end();) {
    if (utime - it->second.last_utime > options_.objects.forget_after_us) {
      it = object_records_.erase(it);
      ++forgotten;
    } else {
      ++it;
    }
  }
  const int64_t links = object_tracking_.stats().segment_ids_forgotten;
  forgotten += links - segment_links_forgotten_;
  segment_links_forgotten_ = links;
  if (forgotten > 0) counters_->Increment(counter::kObjectRecordsPruned, forgotten);
}

void PerceptionCore::OnOdometry(const OdometrySample& odometry) {
  const Status status = odometry_.Insert(odometry.utime, odometry.odom_from_base);
  if (!status.ok()) {
    counters_->Increment(odometry_.empty() || odometry.utime > odometry_.last_utime()
                             ? counter::kOdometryInvalid
                             : counter::kOdometryTimeBackwards);
  }
}

std::optional<RelativeMotion> PerceptionCore::OdometryMotion(int64_t ref_frame,
                                                             int64_t cur_frame) const {
  if (!options_.odometry.use_for_ego_motion) return std::nullopt;
  auto r = frame_utime_.find(ref_frame);
  auto n = frame_utime_.find(cur_frame);
  if (r == frame_utime_.end() || n == frame_utime_.end()) return std::nullopt;
  Rigid3d odom_from_base_r, odom_from_base_n;
  if (odometry_.Interpolate(r->second, &odom_from_base_r) != InterpolationResult::kOk ||
      odometry_.Interpolate(n->second, &odom_from_base_n) != InterpolationResult::kOk) {
    return std::nullopt;
  }
  const Rigid3d odom_from_cam_r = odom_from_base_r * base_from_cam_;
  const Rigid3d odom_from_cam_n = odom_from_base_n * base_from_cam_;
  RelativeMotion m;
  m.cam_n_from_cam_r = odom_from_cam_n.Inverse() * odom_from_cam_r;
  m.source = RelativeMotion::Source::kOdometry;
  m.scale_known = true;
  m.translation_known = m.cam_n_from_cam_r.translation.norm() > options_.odometry.sigma_translation_floor_m;
  // Odometry noise grows with the distance travelled and the angle turned (sec. 3.8.3).
  const double dist = m.cam_n_from_cam_r.translation.norm();
  const double angle = RotationDistance(m.cam_n_from_cam_r, Rigid3d());
  const double st = options_.odometry.sigma_translation_floor_m + options_.odometry.sigma_translation_per_m * dist;
  const double sr = options_.odometry.sigma_rotation_floor_rad + options_.odometry.sigma_rotation_per_rad * angle;
  m.covariance = Matrix6d::Zero();
  m.covariance.topLeftCorner<3, 3>() = st * st * Eigen::Matrix3d::Identity();
  m.covariance.bottomRightCorner<3, 3>() = sr * sr * Eigen::Matrix3d::Identity();
  return m;
}

std::optional<Rigid3d> PerceptionCore::OdometryCameraPose(int64_t utime) const {
  Rigid3d odom_from_base;
  const InterpolationResult r = odometry_.Interpolate(utime, &odom_from_base);
  if (r == InterpolationResult::kOk) return odom_from_base * base_from_cam_;
  // Slightly newer than the last sample (realtime): extrapolate with the last motion.
  if (r == InterpolationResult::kAfterLast && odometry_.size() >= 2 &&
      utime - odometry_.last_utime() <= options_.odometry.max_extrapolation_us) {
    if (odometry_.Extrapolate(utime, &odom_from_base)) return odom_from_base * base_from_cam_;
  }
  return std::nullopt;
}

void PerceptionCore::FillCameraPose(const SlamPose& pose, CameraPoseOutput* out) const {
  switch (pose.state) {
    case SlamState::kNotInitialized: out->tracking_state = TrackingState::kNotInitialized; break;
    case SlamState::kInitializing:
    case SlamState::kConfirming: out->tracking_state = TrackingState::kInitializing; break;
    case SlamState::kTracking:
      out->tracking_state = pose.relocalized ? TrackingState::kRelocalized : TrackingState::kOk;
      break;
    case SlamState::kLost: out->tracking_state = TrackingState::kLost; break;
  }
  if (!pose.valid) {
    if (out->tracking_state == TrackingState::kOk) out->tracking_state = TrackingState::kInitializing;
    return;
  }
  out->world_from_cam = pose.cam_from_world.Inverse();
  // Left perturbation of world_from_cam = T^-1: Exp(-Ad(T^-1) xi) T^-1.
  const Matrix6d ad = out->world_from_cam.Adjoint();
  out->covariance = ad * pose.covariance * ad.transpose();
  out->scale_state = pose.metric ? ScaleState::kMetric : ScaleState::kUpToScale;
  out->scale_to_metric = pose.scale_to_metric;
  out->num_inliers = pose.num_inliers;
  out->num_keyframes = static_cast<int>(slam_.map().num_keyframes());
}

void PerceptionCore::AlignOnWarpedReferences(const Rigid3d& cam_from_world, const CameraIntrinsics& intrinsics,
                                             SlamFrame* slam_frame) {
  const Map& map = slam_.map();
  // References are keyed by their keyframe's image index (keyframe ids restart with a
  // new map; image indices do not).
  std::unordered_map<int64_t, const Keyframe*> keyframe_of_image;
  for (const auto& [id, kf] : map.keyframes()) keyframe_of_image[kf.frame_index] = &kf;
  const double ground_band = options_.tracking.warp_ground_band;
  const double rereference_scale = options_.tracking.warp_rereference_scale;
  std::optional<double> camera_height;
  if (ground_) camera_height = ground_->Height(cam_from_world.Inverse().translation);
  // Static as SLAM sees it: without segmentation feedback (the ablation) every map
  // track is.
  const bool use_labels = options_.slam.use_segmentation;
  std::vector<WarpedReference> warps;
  for (const Track& t : tracker_.tracks()) {
    if (!t.active() || t.last_seen_frame != frame_index_ || (use_labels && t.body_id != 0)) continue;
    if ((t.id + frame_index_) % options_.tracking.warp_align_every != 0) continue;
    const int64_t pid = map.PointOfTrack(t.id);
    const MapPoint* point = pid >= 0 ? map.point(pid) : nullptr;
    if (point == nullptr) continue;
    auto kf_it = keyframe_of_image.find(t.warp_reference_key);
    const Keyframe* kf = kf_it != keyframe_of_image.end() ? kf_it->second : nullptr;
    if (kf == nullptr) {
      rereference_tracks_.insert(t.id);
      continue;
    }
    const Eigen::Vector3d ref_centre = kf->cam_from_world.Inverse().translation;
    Eigen::Vector3d normal = ref_centre - point->position;
    if (camera_height && *camera_height > 0.0 &&
        std::abs(ground_->Height(point->position)) < ground_band * *camera_height) {
      normal = ground_->normal;
    }
    const std::optional<Eigen::Matrix2d> warp = PlaneInducedAffineWarp(
        intrinsics, kf->cam_from_world, cam_from_world, t.warp_reference_uv.cast<double>(), point->position, normal);
    if (!warp) {
      rereference_tracks_.insert(t.id);
      continue;
    }
    const Eigen::Vector2d sv = SingularValues2x2(*warp);
    // (Warps beyond tracking.warp_max_scale are skipped by the tracker itself.)
    if (sv[0] > rereference_scale || sv[1] < 1.0 / rereference_scale) rereference_tracks_.insert(t.id);
    warps.push_back({t.id, warp->cast<float>()});
  }
  const WarpAlignStats stats = tracker_.AlignToReferences(warps);
  MBSLAM_LOG(DEBUG) << "image " << frame_index_ << ": warp alignment tried " << stats.tried << ", corrected "
                    << stats.corrected << " (mean " << stats.mean_correction_px << " px), refused " << stats.refused;
  if (stats.corrected == 0) return;
  std::unordered_map<int64_t, const Track*> track_of;
  for (const Track& t : tracker_.tracks()) {
    if (t.active() && t.last_seen_frame == frame_index_) track_of[t.id] = &t;
  }
  for (SlamObservation& o : slam_frame->observations) {
    auto it = track_of.find(o.track_id);
    if (it == track_of.end()) continue;
    const Eigen::Vector2d uv = it->second->uv.cast<double>();
    if (uv == o.uv) continue;
    o.uv = uv;
    o.xy = intrinsics.PixelToNormalized(uv);
    o.patch = it->second->patch;
  }
}

void PerceptionCore::SetWarpReferences() {
  const Keyframe* kf = slam_.map().LastKeyframe();
  if (kf == nullptr || kf->frame_index != frame_index_) return;
  std::vector<std::pair<int64_t, int64_t>> keys;
  const bool use_labels = options_.slam.use_segmentation;  // as in AlignOnWarpedReferences
  for (const Track& t : tracker_.tracks()) {
    if (!t.active() || t.last_seen_frame != frame_index_ || (use_labels && t.body_id != 0)) continue;
    if (t.warp_reference_key >= 0 && !rereference_tracks_.count(t.id)) continue;
    if (slam_.map().PointOfTrack(t.id) < 0) continue;
    keys.emplace_back(t.id, kf->frame_index);
  }
  tracker_.SetWarpReferences(keys);
  rereference_tracks_.clear();
}

void PerceptionCore::UpdateGroundPlane() {
  const Map& map = slam_.map();
  if (map.num_points() < 30 || map.keyframes().empty()) return;
  std::vector<Eigen::Vector3d> points;
  points.reserve(map.num_points());
  std::vector<int64_t> ids;
  for (const auto& kv : map.points()) ids.push_back(kv.first);
  std::sort(ids.begin(), ids.end());  // deterministic RANSAC input order
  for (int64_t id : ids) points.push_back(map.point(id)->position);
  // Up: minus the first keyframe camera's y axis (cameras are held roughly level).
  const Rigid3d& first = map.keyframes().begin()->second.cam_from_world;
  const Eigen::Vector3d up = -(first.RotationMatrix().transpose() * Eigen::Vector3d::UnitY());
  const Eigen::Vector3d camera = map.LastKeyframe()->cam_from_world.Inverse().translation;
  // A camera at a known height rides at a constant height: its travel lies in a plane
  // parallel to the ground.
  std::vector<Eigen::Vector3d> centres;
  if (options_.objects.camera_height_m > 0.0) {
    for (const auto& [id, k] : map.keyframes()) centres.push_back(k.cam_from_world.Inverse().translation);
  }
  GroundPlaneEstimate estimate;
  bool along_path = false;
  if (!EstimateGroundPlaneAlongTravel(points, up, centres, camera, options_.ground, &estimate, &along_path).ok()) {
    return;
  }
  ground_ = estimate.plane;
  slam_.SetGroundPlane(ground_->ToVector4());
  MBSLAM_LOG(DEBUG) << "ground plane: n " << estimate.plane.normal.transpose() << " d " << estimate.plane.offset
                    << ", inliers " << estimate.num_inliers << " (" << estimate.inlier_ratio << "), rms " << estimate.rms
                    << ", camera height " << estimate.plane.Height(camera) << (along_path ? ", parallel to the path" : "");
}

DepthBound PerceptionCore::DepthBoundFor(int64_t track_id, const Eigen::Vector2d& xy, int64_t frame) const {
  DepthBound bound = slam_.DepthBoundFor(track_id, xy, frame);
  if (!ground_) return bound;
  const std::optional<Rigid3d> cam_from_world = slam_.PoseOfFrame(frame);
  if (!cam_from_world) return bound;
  // A static point lies on or above the ground: along a ray that meets the ground in
  // front of the camera, its depth is at most where the ray meets it (thesis 5.1.1:
  // the ground plane cue; here it bounds the flow vector of sec. 3.5.2).
  const Rigid3d world_from_cam = cam_from_world->Inverse();
  const Eigen::Vector3d c = world_from_cam.translation;
  const Eigen::Vector3d d = world_from_cam.rotation * xy.homogeneous();  // depth 1 along the ray
  const double nd = ground_->normal.dot(d);
  // Elevation of the ray below the horizon: near the horizon a small error of the
  // plane's tilt moves the intersection far, so the margin grows as the angle shrinks.
  const double elevation = std::asin(std::clamp(-nd / d.norm(), -1.0, 1.0));
  const double min_elevation = options_.ground.depth_bound_min_elevation_deg * M_PI / 180.0;
  if (elevation < min_elevation) return bound;
  const double z_ground = -ground_->Height(c) / nd;
  if (z_ground <= 0.0) return bound;
  const double cap = GroundDepthCap(z_ground, elevation, options_.ground.depth_bound_margin,
                                    options_.ground.depth_bound_tilt_sigma_deg);
  bound.z_max = std::min(bound.z_max, cap);
  if (bound.z_min > bound.z_max) bound.z_min = 0.0;  // the map point itself is below ground: not trusted
  return bound;
}

void PerceptionCore::CountOccupancyCrops() {
  if (!occupancy_ || occupancy_->crops() == occupancy_crops_counted_) return;
  counters_->Increment(counter::kOccupancyCrops, occupancy_->crops() - occupancy_crops_counted_);
  counters_->Increment(counter::kOccupancyVoxelsDropped, occupancy_->occupied_voxels_dropped() - occupancy_dropped_counted_);
  occupancy_crops_counted_ = occupancy_->crops();
  occupancy_dropped_counted_ = occupancy_->occupied_voxels_dropped();
}

void PerceptionCore::UpdateOccupancy(const SlamMapUpdate& update, int64_t utime, double focal_px,
                                     const std::vector<std::vector<Eigen::Vector2d>>& moving_hulls_xy,
                                     FrameResult* result) {
  if (!options_.occupancy_enabled) return;
  ScopedStageTimer timer(occupancy_timer_);
  const OccupancyMap::Units units = slam_.metric() ? OccupancyMap::Units::kMetres : OccupancyMap::Units::kUpToScale;
  if (update.rescaled_by && occupancy_) {
    const Status s = occupancy_->Rescale(*update.rescaled_by, units);
    CountOccupancyCrops();  // the rebuild applies the memory bound too
    if (!s.ok()) {
      MBSLAM_LOG(WARNING) << "occupancy rescale: " << s.message() << "; starting a new occupancy map";
      occupancy_.reset();
    }
  }
  if (!update.new_keyframe || update.new_point_ids.empty()) return;
  if (!occupancy_) {
    occupancy_ = std::make_unique<OccupancyMap>(options_.occupancy, units);
    occupancy_crops_counted_ = 0;
    occupancy_dropped_counted_ = 0;
  }
  const Keyframe* kf = slam_.map().LastKeyframe();
  if (kf == nullptr) return;
  // Rays from the keyframe's camera centre to the points triangulated there (sec. 6.3);
  // only static points ever enter the map.
  std::vector<Eigen::Vector3d> points;
  points.reserve(update.new_point_ids.size());
  for (int64_t id : update.new_point_ids) {
    if (const MapPoint* p = slam_.map().point(id)) points.push_back(p->position);
  }
  const Eigen::Vector3d center = kf->cam_from_world.Inverse().translation;
  // Interpolated rays (dense_rays.h): inside the image triangulation of every static
  // point the keyframe sees, sampled at the map's voxel size (so only once it is fixed:
  // the keyframe that fixes it gets them in a second scan). Each point's depth
  // uncertainty comes from the widest parallax among the keyframes observing it.
  const DenseRayOptions& dense = options_.occupancy.dense;
  auto interpolated = [&]() {
    DenseRayInput in;
    in.cam_from_world = kf->cam_from_world;
    in.focal_px = focal_px;
    in.voxel = occupancy_->resolution();
    in.moving_hulls_xy = moving_hulls_xy;
    in.points_in_world.reserve(kf->point_ids.size());
    in.depth_sigma.reserve(kf->point_ids.size());
    const double bearing_sigma = dense.bearing_sigma_px / focal_px;
    std::vector<Eigen::Vector3d> centers;
    for (int64_t id : kf->point_ids) {
      const MapPoint* p = slam_.map().point(id);
      if (p == nullptr) continue;
      centers.clear();
      for (const Observation& o : p->observations) {
        if (o.keyframe_id == kf->id) continue;
        if (const Keyframe* other = slam_.map().keyframe(o.keyframe_id)) {
          centers.push_back(other->cam_from_world.Inverse().translation);
        }
      }
      in.points_in_world.push_back(p->position);
      in.depth_sigma.push_back(TriangulationDepthSigma(p->position, center, centers, bearing_sigma));
    }
    DenseRayStats stats;
    std::vector<Eigen::Vector3d> samples = DensifyKeyframe(in, dense, &stats);
    MBSLAM_LOG(DEBUG) << "occupancy: keyframe " << kf->id << " " << stats.points << " points ("
                      << stats.uncertain << " too uncertain), " << stats.triangles << " triangles, "
                      << stats.triangles_used << " used (rejected: edge " << stats.rejected_edge << ", depth "
                      << stats.rejected_depth << ", incidence " << stats.rejected_incidence << ", moving "
                      << stats.rejected_moving << "), " << stats.samples << " samples, spacing x"
                      << stats.spacing_scale;
    return samples;
  };
  if (dense.enabled && occupancy_->IsResolutionFixed()) {
    occupancy_->InsertRays(center, points, interpolated());
  } else {
    occupancy_->InsertRays(center, points);
    if (dense.enabled && occupancy_->IsResolutionFixed()) occupancy_->InsertRays(center, {}, interpolated());
  }
  CountOccupancyCrops();
  if (!occupancy_->IsResolutionFixed()) return;
  // Serialising a large tree costs tens of ms: publish at most once per period.
  if (last_occupancy_publish_utime_ && utime - *last_occupancy_publish_utime_ < options_.occupancy_publish_period_us) return;
  last_occupancy_publish_utime_ = utime;
  OccupancyOutput out;
  out.utime = utime;
  out.scale_state = slam_.metric() ? ScaleState::kMetric : ScaleState::kUpToScale;
  out.resolution = occupancy_->resolution();
  out.num_occupied = static_cast<int>(occupancy_->NumOccupied());
  out.memory_bytes = occupancy_->MemoryBytes();
  if (occupancy_->Serialize(&out.octree_binary).ok()) result->occupancy = std::move(out);
}

void PerceptionCore::FillObjectEstimate(const TrackedObject& t, ObjectOutput* out) const {
  const BotEstimate& e = t.estimate;
  out->state = e.reliable ? ObjectState::kTracked : ObjectState::kDetected;
  // The published pose is the object's box centre (the filter follows a reference point
  // on its visible surface; the extent gives the offset).
  out->world_from_object = e.world_from_object;
  out->world_from_object.translation = t.center;
  out->pose_covariance = e.pose_covariance;
  out->linear_velocity = e.linear_velocity;
  out->angular_velocity = e.angular_velocity;
  out->velocity_covariance = e.velocity_covariance;
  out->depth = e.depth;
  out->depth_sigma = e.depth_sigma;
  out->num_particles = e.num_particles;
  out->effective_sample_size = e.effective_sample_size;
  out->particle_samples = e.particle_samples;
  if (t.extent.valid) out->extent = t.extent.SizeAlong(e.world_from_object.rotation);
  if (e.relative_scale) {
    out->relative_scale = e.relative_scale->scale;
    out->relative_scale_sigma = e.relative_scale->sigma;
  }
  for (const PredictedVolume& v : t.volumes) {
    PredictedVolumeOutput pv;
    pv.utime = v.utime;
    pv.horizon_us = v.horizon_us;
    pv.center = v.center;
    pv.orientation = v.orientation;
    pv.half_extent = v.half_extent;
    pv.probability = v.probability;
    out->volumes.push_back(pv);
  }
}

MapOutput PerceptionCore::BuildMapOutput(int64_t utime) const {
  MapOutput m;
  m.utime = utime;
  m.scale_state = slam_.metric() ? ScaleState::kMetric : ScaleState::kUpToScale;
  const Map& map = slam_.map();
  std::vector<int64_t> ids;
  ids.reserve(map.num_points());
  for (const auto& kv : map.points()) ids.push_back(kv.first);
  std::sort(ids.begin(), ids.end());  // deterministic order
  for (int64_t id : ids) {
    const MapPoint& p = *map.point(id);
    m.point_ids.push_back(id);
    m.points.push_back(p.position.cast<float>());
    m.colors.push_back({p.gray, p.gray, p.gray});
  }
  for (const auto& [id, k] : map.keyframes()) {
    KeyframeOutput kf;
    kf.id = id;
    kf.utime = k.utime;
    kf.world_from_cam = k.cam_from_world.Inverse();
    kf.num_observations = static_cast<int>(k.point_ids.size());
    m.keyframes.push_back(kf);
  }
  if (ground_) m.ground_plane = ground_->ToVector4();
  return m;
}

FrameResult PerceptionCore::ProcessFrame(const ImageFrame& frame) {
  if (frame.timeline_reset) {
    MBSLAM_LOG(WARNING) << "image time went back for good at " << frame.utime << ": starting over";
    Reset();
  }
  ++frame_index_;
  frame_utime_[frame_index_] = frame.utime;
  if (global_ba_request_.exchange(false)) {
    counters_->Increment(counter::kGlobalBaRequested);
    slam_.RequestGlobalBundleAdjustment();
  }
  // As far back as the odometry motions of the segmentation reach, and as the poses SLAM
  // may back-fill (their times are looked up here).
  const size_t keep_utimes = 64 + static_cast<size_t>(std::max(0, options_.slam.backfill_max_frames));
  while (frame_utime_.size() > keep_utimes) frame_utime_.erase(frame_utime_.begin());

  FrameResult result;
  result.utime = frame.utime;
  result.frame_seq = frame.seq;
  result.width = frame.gray.cols;
  result.height = frame.gray.rows;
  result.camera_pose.utime = frame.utime;
  result.camera_pose.frame_seq = frame.seq;
  result.camera_pose.tracking_state = TrackingState::kNotInitialized;
  {
    ScopedStageTimer timer(preprocess_timer_);
    // A fresh pyramid every image: the tracker keeps the previous one (shallow Mats),
    // so buffers must not be reused.
    pyramid_ = std::vector<cv::Mat>();
    // The pyramid's border must hold the KLT window (OpenCV asserts otherwise).
    const int border_win = std::max({21, options_.tracking.klt_window_px, options_.tracking.klt_fast_window_px});
    // OpenCV's KLT reads derivative levels from the pyramid (or computes them per call);
    // the project's KLT differentiates its sampled windows and needs none.
    cv::buildOpticalFlowPyramid(frame.gray, pyramid_, cv::Size(border_win, border_win),
                                options_.preprocess.pyramid_levels - 1,
                                /*withDerivatives=*/options_.tracking.klt_backend == "opencv");
  }

  // Tracking, with the previous image's moving hulls as occluders (feedback from
  // segmentation).
  {
    ScopedStageTimer timer(tracking_timer_);
    TrackingHints hints;
    hints.occluders = occluders_;
    if (const auto prev = frame_utime_.find(frame_index_ - 1); prev != frame_utime_.end() && frame.utime > prev->second) {
      hints.interval_us = frame.utime - prev->second;
    }
    tracker_.TrackFrame(pyramid_, frame_index_, hints);
  }
  if (GetLogLevel() <= LogLevel::kDebug) {
    const TrackerStats& ts = tracker_.stats();
    MBSLAM_LOG(DEBUG) << "image " << frame.seq << ": KLT tracked " << ts.tracked << ", lost " << ts.lost << " (forward " << ts.lost_forward
                      << ", backward " << ts.lost_backward << ", forward-backward " << ts.lost_consistency
                      << ", border " << ts.lost_border << ", appearance " << ts.lost_appearance << "; established "
                      << ts.established_matched << " of " << ts.established << " kept), created "
                      << ts.created << " (" << ts.created_on_objects << " on moving objects), ORB re-found " << ts.descriptor_matched << ", median flow "
                      << ts.median_flow_px << " px" << (ts.fast_motion ? " (fast-motion KLT)" : "");
  }
  if (tracker_.stats().exposure_corrected) {
    MBSLAM_LOG(INFO) << "image " << frame.seq << ": exposure step undone (gain " << tracker_.stats().exposure_gain
                     << ", offset " << tracker_.stats().exposure_offset << ")";
    counters_->Increment(counter::kImageExposureCorrected);
  }
  if (tracker_.stats().rejected) {
    // A glitch image (flash, corrupted or foreign frame): no pose and no change to any
    // state; the next image is tracked from the last good one.
    MBSLAM_LOG(WARNING) << "image " << frame.seq << " rejected as a glitch: " << tracker_.stats().established_matched
                        << " of " << tracker_.stats().established << " established tracks matched";
    counters_->Increment(counter::kImageRejectedGlitch);
    frame_utime_.erase(frame_index_);
    --frame_index_;
    result.camera_pose.tracking_state = slam_.initialized() ? TrackingState::kLost : TrackingState::kNotInitialized;
    return result;
  }

  // SLAM, step 1: the camera pose against the static map, with the previous labels.
  const CameraIntrinsics& intrinsics = *frame.intrinsics;
  SlamFrame slam_frame;
  slam_frame.frame_index = frame_index_;
  slam_frame.utime = frame.utime;
  slam_frame.focal_px = 0.5 * (intrinsics.fx + intrinsics.fy);
  slam_frame.mean_gray = static_cast<uint8_t>(cv::mean(frame.gray)[0]);
  if (options_.slam.use_odometry) slam_frame.odom_from_cam = OdometryCameraPose(frame.utime);
  for (const Track& t : tracker_.tracks()) {
    if (!t.active()) continue;
    SlamObservation o;
    o.track_id = t.id;
    o.uv = t.uv.cast<double>();
    o.xy = intrinsics.PixelToNormalized(o.uv);
    o.body_id = options_.slam.use_segmentation ? t.body_id : 0;
    o.p_static = options_.slam.use_segmentation ? t.p_static : 1.0;
    o.is_new = t.is_new;
    o.patch = t.patch;
    slam_frame.observations.push_back(o);
  }
  slam_frame.image = frame.gray;
  slam_frame.intrinsics = frame.intrinsics.get();
  for (const TrackingHints::Hull& h : occluders_) {
    std::vector<Eigen::Vector2f> xy;
    for (const Eigen::Vector2f& p : h.points) xy.push_back(intrinsics.PixelToNormalized(p.cast<double>()).cast<float>());
    slam_frame.moving_hulls_xy.push_back(std::move(xy));
  }
  SlamPose slam_pose;
  {
    ScopedStageTimer timer(slam_timer_);
    slam_pose = slam_.TrackPose(slam_frame);
    if (slam_pose.epipolar_assisted) counters_->Increment(counter::kPoseEpipolarAssisted);
    if (slam_pose.placed_by_relocalization && slam_pose.valid) {
      counters_->Increment(counter::kPoseRelocalized);
    }
    if (slam_pose.rejoined_kept_map) counters_->Increment(counter::kMapRejoined);
    // Re-found map points become tracks again (they rejoin the segmentation as static).
    for (const auto& [point_id, uv] : slam_pose.refound) {
      const int64_t track_id = tracker_.AdoptTrack(uv, 0);
      if (track_id < 0) {
        // In a map that relocalised, re-found points are often corners the tracker's own
        // detector found too: the track already there, if it holds no point and is not
        // held moving, takes the point.
        if (slam_pose.relocalized_map) {
          const int64_t here = UnmappedTrackAt(uv, kRelocalizedTrackRadiusPx);
          if (here >= 0) slam_.AssociateTrack(point_id, here);
        }
        continue;
      }
      slam_.AssociateTrack(point_id, track_id);
      SlamObservation o;
      o.track_id = track_id;
      o.uv = uv.cast<double>();
      o.xy = intrinsics.PixelToNormalized(o.uv);
      o.body_id = 0;
      o.p_static = 0.9;
      slam_frame.observations.push_back(o);
    }
  }

  if (options_.tracking.warp_align && slam_pose.valid && slam_pose.state == SlamState::kTracking) {
    ScopedStageTimer timer(warp_timer_);
    AlignOnWarpedReferences(slam_pose.cam_from_world, intrinsics, &slam_frame);
  }

  // Segmentation on the active tracks.
  SegmentationResult seg;
  {
    ScopedStageTimer timer(segmentation_timer_);
    const CameraIntrinsics& K = intrinsics;
    SegmenterInput in;
    in.frame_index = frame_index_;
    in.width = frame.gray.cols;
    in.height = frame.gray.rows;
    in.focal_px = 0.5 * (K.fx + K.fy);
    in.K = K.K();
    for (const SlamObservation& so : slam_frame.observations) {
      TrackObservation o;
      o.id = so.track_id;
      o.uv = so.uv;
      o.xy = so.xy;
      in.observations.push_back(o);
    }
    // World motion: SLAM's poses when the map tracks (with its depth bounds), else
    // odometry, else the segmenter's own two-view estimate.
    in.world_motion = [this](int64_t r, int64_t n) -> std::optional<RelativeMotion> {
      if (auto m = slam_.RelativeMotionBetween(r, n)) return m;
      return OdometryMotion(r, n);
    };
    if (slam_.initialized()) {
      in.depth_bound = [this](int64_t id, const Eigen::Vector2d& xy, int64_t r) {
        return DepthBoundFor(id, xy, r);
      };
    } else if (options_.odometry.use_for_ego_motion && !odometry_.empty()) {
      const double zmin = options_.odometry.min_depth_m;
      const double zmax = options_.odometry.max_depth_m > 0.0 ? options_.odometry.max_depth_m
                                                              : std::numeric_limits<double>::infinity();
      in.depth_bound = [zmin, zmax](int64_t, const Eigen::Vector2d&, int64_t) {
        return DepthBound{zmin, zmax};
      };
    }
    seg = segmenter_.Update(in);
    if (seg.world_motion_replaced) counters_->Increment(counter::kWorldMotionReplaced);
  }
  if (GetLogLevel() <= LogLevel::kDebug) {
    int moving = 0, unjudged = 0;
    for (const TrackLabel& l : seg.labels) {
      moving += l.evaluated && l.body_id != 0;
      unjudged += !l.evaluated;
    }
    MBSLAM_LOG(DEBUG) << "frame " << frame_index_ << ": tracks " << seg.labels.size() << " moving "
                      << moving << " new " << unjudged << " objects " << seg.objects.size() << " world motion "
                      << (seg.world_motion ? (seg.world_motion->translation_known ? "R,t" : "R only") : "none")
                      << " ref " << seg.world_ref_frame << " pair ground " << seg.pair_ground_inliers;
  }

  // Labels back onto the tracks (feedback to the tracker's occlusion handling).
  std::unordered_map<int64_t, const TrackLabel*> label_of;
  std::unordered_map<int64_t, int> body_of;
  for (const TrackLabel& l : seg.labels) {
    label_of[l.id] = &l;
    body_of[l.id] = l.body_id;
  }
  // Objects whose tracks are still static map points: previously static objects start
  // from their mapped depth (sec. 5.1.2). Read before the map releases those points.
  std::map<int, std::vector<Eigen::Vector3d>> mapped_points_of;
  if (options_.objects.enabled) {
    for (const SegmentedObject& o : seg.objects) {
      for (int64_t id : o.track_ids) {
        const int64_t pid = slam_.map().PointOfTrack(id);
        if (pid < 0) continue;
        if (const MapPoint* p = slam_.map().point(pid)) mapped_points_of[o.id].push_back(p->position);
      }
    }
  }
  // SLAM, step 2: the labels update the map (moving tracks leave it), keyframes, BA.
  SlamMapUpdate map_update;
  {
    ScopedStageTimer timer(mapping_timer_);
    if (options_.slam.use_segmentation) {
      map_update = slam_.UpdateMap(slam_frame, body_of);
    } else {
      std::unordered_map<int64_t, int> all_static;
      for (const auto& [id, body] : body_of) all_static[id] = 0;
      map_update = slam_.UpdateMap(slam_frame, all_static);
    }
    // The new keyframe is the reference appearance of map tracks without a usable one.
    if (map_update.new_keyframe && options_.tracking.warp_align) SetWarpReferences();
  }
  // Bundle adjustment time per run (solver wall time; in the back-end thread when
  // slam.background_ba, so not part of this image's time), recorded when a run is merged.
  if (slam_.ba_runs() != ba_runs_seen_) {
    ba_runs_seen_ = slam_.ba_runs();
    (slam_.last_ba_requested() ? global_ba_timer_ : ba_timer_)->Add(slam_.last_ba_seconds() * 1e3);
  }
  if (slam_.requested_ba_runs() != requested_ba_runs_seen_) {
    counters_->Increment(counter::kGlobalBaStarted,
                         slam_.requested_ba_runs() - requested_ba_runs_seen_);
    requested_ba_runs_seen_ = slam_.requested_ba_runs();
  }
  if (map_update.culled_points > 0) counters_->Increment(counter::kMapPointsCulled, map_update.culled_points);
  // The metric rescale comes with a new keyframe: the plane is rescaled first, so that a
  // fit in the new units is not rescaled again (it was, before).
  if (map_update.rescaled_by && ground_) ground_->Rescale(*map_update.rescaled_by);
  if (map_update.new_keyframe) UpdateGroundPlane();
  {
    // This image's moving objects, and those predicted for it: no static evidence there.
    std::vector<std::vector<Eigen::Vector2d>> moving_hulls_xy;
    if (options_.occupancy_enabled && map_update.new_keyframe) {
      for (const SegmentedObject& o : seg.objects) {
        std::vector<Eigen::Vector2d> xy;
        for (const Eigen::Vector2d& p : o.hull) xy.push_back(intrinsics.PixelToNormalized(p));
        if (xy.size() >= 3) moving_hulls_xy.push_back(std::move(xy));
      }
      for (const std::vector<Eigen::Vector2f>& h : slam_frame.moving_hulls_xy) {
        std::vector<Eigen::Vector2d> xy;
        for (const Eigen::Vector2f& p : h) xy.push_back(p.cast<double>());
        if (xy.size() >= 3) moving_hulls_xy.push_back(std::move(xy));
      }
    }
    UpdateOccupancy(map_update, frame.utime, 0.5 * (intrinsics.fx + intrinsics.fy), moving_hulls_xy, &result);
  }
  FillCameraPose(slam_pose, &result.camera_pose);
  for (const auto& [f, cam_from_world] : slam_pose.backfilled) {
    auto u = frame_utime_.find(f);
    if (u == frame_utime_.end()) {
      // Its image time is gone (kept for 64 + slam.backfill_max_frames images): said, not hidden.
      MBSLAM_LOG(WARNING) << "back-filled pose of image " << f << " dropped: its time is no longer kept";
      continue;
    }
    Rigid3d world_from_cam = cam_from_world.Inverse();
    if (map_update.rescaled_by) world_from_cam.translation *= *map_update.rescaled_by;
    result.backfilled_camera_poses.emplace_back(u->second, world_from_cam);
  }
  result.world_rescaled_by = map_update.rescaled_by;
  if (map_update.rescaled_by && result.camera_pose.tracking_state != TrackingState::kNotInitialized) {
    // This image's pose was computed before the rescale.
    result.camera_pose.world_from_cam.translation *= *map_update.rescaled_by;
    result.camera_pose.scale_state = ScaleState::kMetric;
    result.camera_pose.scale_to_metric = 1.0;
  }
  if (slam_.map().num_keyframes() > 0 &&
      (map_update.new_keyframe || frame_index_ - last_map_publish_frame_ >= options_.map_publish_every_frames)) {
    ScopedStageTimer timer(outputs_timer_);
    result.map = BuildMapOutput(frame.utime);
    last_map_publish_frame_ = frame_index_;
  }
  for (Track& t : tracker_.tracks()) {
    auto it = label_of.find(t.id);
    if (it == label_of.end()) continue;
    t.body_id = it->second->body_id;
    t.p_static = static_cast<float>(it->second->p_static);
  }

  // Each segmented object's tracks seen in this image (ids, normalised bearings), for the
  // object reconstructions and the object filters.
  std::unordered_map<int64_t, Eigen::Vector2d> xy_of;
  for (const SlamObservation& so : slam_frame.observations) xy_of[so.track_id] = so.xy;
  std::vector<ObjectTracksInput> object_tracks;
  for (const SegmentedObject& o : seg.objects) {
    ObjectTracksInput in;
    in.id = o.id;
    for (int64_t id : o.track_ids) {
      auto it = xy_of.find(id);
      if (it == xy_of.end()) continue;
      in.track_ids.push_back(id);
      in.xy.push_back(it->second);
    }
    object_tracks.push_back(std::move(in));
  }
  // Each moving object with enough tracks gets its own SLAM (sec. 4.1): the camera w.r.t.
  // the object and the object's points, in its own scale.
  std::map<int, ObjectReconstructionResult> reconstruction_of;  // by segment id
  if (options_.object_slam.enabled) {
    ScopedStageTimer timer(object_slam_timer_);
    std::optional<CameraRotationPrior> world_rotation;
    if (slam_pose.valid && slam_pose.state == SlamState::kTracking) {
      world_rotation = CameraRotationPrior{slam_pose.cam_from_world.rotation, slam_.map_generation()};
    }
    for (ObjectReconstructionResult& r : object_reconstruction_->Update(
             frame_index_, frame.utime, 0.5 * (intrinsics.fx + intrinsics.fy), object_tracks, world_rotation)) {
      reconstruction_of[r.id] = std::move(r);
    }
  }

  // Bearing-only tracking of every moving object (ch. 5-6).
  std::map<int, const TrackedObject*> tracked_of;
  const std::vector<TrackedObject>* tracked = nullptr;
  if (options_.objects.enabled) {
    ScopedStageTimer timer(objects_timer_);
    ObjectFrame of;
    of.utime = frame.utime;
    of.pose_valid = slam_pose.valid && slam_pose.state == SlamState::kTracking;
    of.cam_from_world = slam_pose.cam_from_world;
    // This image's pose was computed before a rescale of the world in this image.
    if (map_update.rescaled_by) of.cam_from_world.translation *= *map_update.rescaled_by;
    of.focal_px = 0.5 * (intrinsics.fx + intrinsics.fy);
    of.metric = slam_.metric();
    of.ground = ground_;
    of.rescaled_by = map_update.rescaled_by;
    for (size_t k = 0; k < seg.objects.size(); ++k) {
      const SegmentedObject& o = seg.objects[k];
      ObjectObservation ob;
      ob.id = o.id;
      ob.track_ids = object_tracks[k].track_ids;
      ob.track_xy = object_tracks[k].xy;
      if (ob.track_xy.empty()) continue;
      Eigen::Vector2d c = Eigen::Vector2d::Zero();
      for (const Eigen::Vector2d& p : ob.track_xy) c += p;
      c /= static_cast<double>(ob.track_xy.size());
      // The static world behind the object bounds its depth (sec. 5.1.1).
      const DepthBound b = DepthBoundFor(-1, c, frame_index_);
      if (std::isfinite(b.z_max) && b.z_max > 0.0) {
        const double f = map_update.rescaled_by ? *map_update.rescaled_by : 1.0;
        ob.background_depth = DepthRange{0.0, b.z_max * f};
      }
      if (o.mean_flow_px.allFinite()) ob.flow_xy = o.mean_flow_px / of.focal_px;
      auto rc = reconstruction_of.find(o.id);
      if (options_.object_slam.feedback_to_tracker && rc != reconstruction_of.end() && rc->second.valid) {
        ob.sfm = ObjectObservation::Sfm{rc->second.map_id, rc->second.cam_from_obj, rc->second.median_depth};
      }
      auto mp = mapped_points_of.find(o.id);
      if (mp != mapped_points_of.end()) {
        ob.mapped_points = mp->second;
        if (map_update.rescaled_by) {
          for (Eigen::Vector3d& p : ob.mapped_points) p *= *map_update.rescaled_by;
        }
      }
      of.objects.push_back(std::move(ob));
    }
    tracked = &object_tracking_.Update(of);
    for (const TrackedObject& t : *tracked) tracked_of[t.id] = &t;
  }
  // Segmentation ids -> persistent object ids (the filters keep an object's identity when
  // the segmentation re-labels it, and several segments of one object share its id).
  std::map<int, int> object_id_of;
  for (const SegmentedObject& o : seg.objects) {
    object_id_of[o.id] = options_.objects.enabled ? object_tracking_.PersistentId(o.id) : o.id;
  }

  // Person checks run on the other core, one image behind: the checks launched with the
  // previous image are collected here (in lockstep waiting if they are not done, so that
  // the result is the same every run; live only when done), and this image's are
  // launched after its hulls when no job is running.
  {
    ScopedStageTimer timer(person_timer_);
    CollectPersonChecks();
  }
  // Person checks due in this image: at most max_checks_per_frame, the least recently
  // checked first (a burst of new objects would otherwise stall one image).
  std::set<int> person_check_due;
  std::vector<std::pair<int, cv::Rect>> person_boxes;
  if (options_.person.enabled && !person_job_.valid()) {
    std::vector<std::pair<int64_t, int>> due;  // (last check frame, object id)
    for (const SegmentedObject& o : seg.objects) {
      if (o.hull.size() < 3) continue;
      const int oid = object_id_of[o.id];
      auto rec = object_records_.find(oid);
      const std::optional<int64_t> last =
          rec == object_records_.end() ? std::nullopt : rec->second.person_checked_frame;
      const int64_t last_frame = last ? *last : std::numeric_limits<int64_t>::min();
      if (!last || frame_index_ - last_frame >= options_.person.every_n_frames) {
        due.emplace_back(last_frame, oid);
      }
    }
    std::sort(due.begin(), due.end());
    for (size_t k = 0; k < due.size() && static_cast<int>(k) < options_.person.max_checks_per_frame; ++k) {
      person_check_due.insert(due[k].second);
    }
  }

  // Moving objects: hulls, person check, occluders for the next image. One output per
  // persistent id: the segments of one object (fragments) share its hull.
  occluders_.clear();
  std::map<int, std::vector<const SegmentedObject*>> segments_of;
  std::vector<int> object_order;  // first appearance in the segmentation's order
  for (const SegmentedObject& o : seg.objects) {
    const int oid = object_id_of[o.id];
    if (!segments_of.count(oid)) object_order.push_back(oid);
    segments_of[oid].push_back(&o);
    TrackingHints::Hull occ;
    occ.body_id = o.id;
    occ.age_frames = static_cast<int>(std::max<int64_t>(0, frame_index_ - o.first_frame));
    for (const Eigen::Vector2d& p : o.hull) occ.points.push_back((p + o.mean_flow_px).cast<float>());
    if (occ.points.size() >= 3) occluders_.push_back(std::move(occ));
  }
  for (const int oid : object_order) {
    const std::vector<const SegmentedObject*>& parts = segments_of[oid];
    ObjectOutput out;
    out.id = oid;
    out.state = ObjectState::kDetected;
    auto tr = tracked_of.find(oid);
    if (tr != tracked_of.end()) {
      // Seen, or segmented with too few tracks for its filter in this image: the estimate
      // (predicted when not seen).
      FillObjectEstimate(*tr->second, &out);
      tracked_of.erase(tr);
    }
    ObjectRecord& record = RecordOf(oid, frame.utime);
    out.first_seen_utime = record.first_utime;
    HullOutput hull;
    hull.body_id = oid;
    std::vector<Eigen::Vector2f> points;
    for (const SegmentedObject* o : parts) {
      out.num_tracks += static_cast<int>(o->track_ids.size());
      for (const Eigen::Vector2d& p : o->hull) points.push_back(p.cast<float>());
    }
    hull.points = parts.size() == 1 ? points : ConvexHull(points);
    float min_x = 1e9f, min_y = 1e9f, max_x = -1e9f, max_y = -1e9f;
    for (const Eigen::Vector2f& p : hull.points) {
      min_x = std::min(min_x, p.x());
      min_y = std::min(min_y, p.y());
      max_x = std::max(max_x, p.x());
      max_y = std::max(max_y, p.y());
    }
    if (person_check_due.count(oid) && hull.points.size() >= 3) {
      person_boxes.emplace_back(oid, cv::Rect(static_cast<int>(min_x), static_cast<int>(min_y),
                                              static_cast<int>(max_x - min_x), static_cast<int>(max_y - min_y)));
      record.person_checked_frame = frame_index_;
    }
    out.object_class = record.is_person ? ObjectClass::kPerson : ObjectClass::kUnknown;
    // The object's own reconstruction (from its largest segment that has one): its points
    // enter the world at the relative scale (sec. 6.1) once the filter has it.
    for (const SegmentedObject* o : parts) {
      auto rc = reconstruction_of.find(o->id);
      if (rc == reconstruction_of.end() || !rc->second.valid) continue;
      const ObjectReconstructionResult& r = rc->second;
      ObjectReconstructionOutput ro;
      ro.object_id = oid;
      ro.map_id = r.map_id;
      ro.cam_from_obj = r.cam_from_obj;
      ro.num_points = r.num_points;
      if (r.points_included) {
        ro.points_included = true;
        ro.points.reserve(r.points.size());
        for (const Eigen::Vector3d& p : r.points) ro.points.push_back(p.cast<float>());
        record.sfm_map_id = r.map_id;
        record.sfm_points = r.points;
      }
      if (out.relative_scale > 0.0 && record.sfm_map_id == r.map_id && slam_pose.valid) {
        out.state = ObjectState::kReconstructed;
        const Rigid3d world_from_cam = result.camera_pose.world_from_cam;
        out.points.reserve(record.sfm_points.size());
        for (const Eigen::Vector3d& p : record.sfm_points) {
          out.points.push_back((world_from_cam * (out.relative_scale * (r.cam_from_obj * p))).cast<float>());
        }
      }
      result.object_reconstructions.push_back(std::move(ro));
      break;
    }
    out.hull = hull;
    result.hulls.push_back(hull);
    result.objects.push_back(std::move(out));
  }
  // Objects not segmented in this image (occluded, left the view) but recently seen: the
  // filter's prediction, without a hull.
  for (const auto& [id, t] : tracked_of) {
    ObjectOutput out;
    out.id = id;
    const bool known = object_records_.count(id) > 0;
    ObjectRecord& record = RecordOf(id, frame.utime);
    if (!known) record.first_utime = t->last_seen_utime;
    out.first_seen_utime = record.first_utime;
    out.object_class = record.is_person ? ObjectClass::kPerson : ObjectClass::kUnknown;
    FillObjectEstimate(*t, &out);
    result.objects.push_back(std::move(out));
  }
  if (!person_boxes.empty()) {
    // frame.gray is not written after decoding; the job holds a reference to it.
    person_job_ = std::async(std::launch::async, [this, gray = frame.gray, boxes = std::move(person_boxes)] {
      // Below the per-image threads (the next image's KLT runs on both cores meanwhile);
      // raising niceness is always permitted, a failure only keeps the default.
      if (options_.person.job_nice > 0) setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), options_.person.job_nice);
      std::vector<std::pair<int, bool>> found;
      for (const auto& [id, box] : boxes) found.emplace_back(id, person_detector_.Detect(gray, box));
      return found;
    });
  }
  ForgetGoneObjects(frame.utime);
  result.epipole = seg.epipole;

  for (const Track& t : tracker_.tracks()) {
    TrackOutput o;
    o.id = t.id;
    o.uv = t.uv;
    o.prev_uv = t.is_new ? Eigen::Vector2f::Constant(NAN) : t.prev_uv;
    o.age = t.age;
    o.body_id = t.body_id;
    if (o.body_id > 0) {
      auto id = object_id_of.find(o.body_id);
      o.body_id = id != object_id_of.end() ? id->second
                  : options_.objects.enabled ? object_tracking_.PersistentId(o.body_id) : o.body_id;
    }
    o.p_static = t.p_static;
    o.occluded = !t.active();
    o.has_3d = slam_.HasPoint(t.id);
    o.is_new = t.is_new;
    auto it = label_of.find(t.id);
    if (it != label_of.end()) {
      o.epipolar_px = static_cast<float>(it->second->epipolar_px);
      o.fvb = static_cast<float>(it->second->p_fvb);
    }
    result.tracks.push_back(o);
  }
  return result;
}

void PerceptionCore::CollectPersonChecks() {
  if (!person_job_.valid()) return;
  if (!options_.wait_for_person_checks &&
      person_job_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) {
    return;  // live: still running (niced); taken with a later image
  }
  for (const auto& [id, found] : person_job_.get()) {
    auto it = object_records_.find(id);  // forgotten meanwhile: nothing to mark
    if (found && it != object_records_.end()) it->second.is_person = true;
  }
}

}  // namespace mbslam
