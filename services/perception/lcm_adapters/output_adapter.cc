#include "services/perception/lcm_adapters/output_adapter.h"

#include "common/util/logging.h"

namespace mbslam {
namespace {

void PutPose(const Rigid3d& pose, double position[3], double orientation[4]) {
  for (int i = 0; i < 3; ++i) position[i] = pose.translation[i];
  orientation[0] = pose.rotation.w();
  orientation[1] = pose.rotation.x();
  orientation[2] = pose.rotation.y();
  orientation[3] = pose.rotation.z();
}

void PutMatrix6(const Matrix6d& m, double out[36]) {
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) out[r * 6 + c] = m(r, c);
  }
}

mbslam::image_hull_t ToLcm(const HullOutput& hull) {
  mbslam::image_hull_t h{};
  h.body_id = hull.body_id;
  h.num_points = static_cast<int32_t>(hull.points.size());
  for (const auto& p : hull.points) {
    h.u.push_back(p.x());
    h.v.push_back(p.y());
  }
  return h;
}

}  // namespace

mbslam::camera_pose_t ToLcm(const CameraPoseOutput& pose) {
  mbslam::camera_pose_t m{};
  m.utime = pose.utime;
  m.frame_seq = pose.frame_seq;
  PutPose(pose.world_from_cam, m.position, m.orientation);
  PutMatrix6(pose.covariance, m.covariance);
  m.tracking_state = static_cast<int8_t>(pose.tracking_state);
  m.scale_state = static_cast<int8_t>(pose.scale_state);
  m.scale_to_metric = pose.scale_to_metric;
  m.num_inliers = pose.num_inliers;
  m.num_keyframes = pose.num_keyframes;
  return m;
}

mbslam::tracks_t ToLcmTracks(const FrameResult& r) {
  mbslam::tracks_t m{};
  m.utime = r.utime;
  m.frame_seq = r.frame_seq;
  m.width = r.width;
  m.height = r.height;
  for (int i = 0; i < 3; ++i) m.epipole[i] = r.epipole[i];
  m.num_tracks = static_cast<int32_t>(r.tracks.size());
  m.tracks.reserve(r.tracks.size());
  for (const TrackOutput& t : r.tracks) {
    mbslam::feature_track_t f{};
    f.id = t.id;
    f.u = t.uv.x();
    f.v = t.uv.y();
    f.prev_u = t.prev_uv.x();
    f.prev_v = t.prev_uv.y();
    f.age = t.age;
    f.body_id = t.body_id;
    f.p_static = t.p_static;
    f.epipolar_px = t.epipolar_px;
    f.fvb = t.fvb;
    f.flags = static_cast<int8_t>((t.has_3d ? mbslam::feature_track_t::FLAG_HAS_3D : 0) |
                                  (t.occluded ? mbslam::feature_track_t::FLAG_OCCLUDED : 0) |
                                  (t.is_new ? mbslam::feature_track_t::FLAG_NEW : 0));
    m.tracks.push_back(f);
  }
  m.num_hulls = static_cast<int32_t>(r.hulls.size());
  for (const HullOutput& h : r.hulls) m.hulls.push_back(ToLcm(h));
  return m;
}

mbslam::objects_t ToLcmObjects(const FrameResult& r) {
  mbslam::objects_t m{};
  m.utime = r.utime;
  m.frame_seq = r.frame_seq;
  m.scale_state = static_cast<int8_t>(r.camera_pose.scale_state);
  m.num_objects = static_cast<int32_t>(r.objects.size());
  for (const ObjectOutput& o : r.objects) {
    mbslam::object_t x{};
    x.id = o.id;
    x.state = static_cast<int8_t>(o.state);
    x.object_class = static_cast<int8_t>(o.object_class);
    x.first_seen_utime = o.first_seen_utime;
    x.num_tracks = o.num_tracks;
    PutPose(o.world_from_object, x.position, x.orientation);
    PutMatrix6(o.pose_covariance, x.pose_covariance);
    for (int i = 0; i < 3; ++i) {
      x.linear_velocity[i] = o.linear_velocity[i];
      x.angular_velocity[i] = o.angular_velocity[i];
      x.extent[i] = o.extent[i];
    }
    PutMatrix6(o.velocity_covariance, x.velocity_covariance);
    x.depth = o.depth;
    x.depth_sigma = o.depth_sigma;
    x.relative_scale = o.relative_scale;
    x.relative_scale_sigma = o.relative_scale_sigma;
    x.hull = ToLcm(o.hull);
    x.num_particles = o.num_particles;
    x.effective_sample_size = o.effective_sample_size;
    x.num_particle_samples = static_cast<int32_t>(o.particle_samples.size());
    for (const auto& p : o.particle_samples) x.particle_samples.push_back({p.x(), p.y(), p.z()});
    x.num_points = static_cast<int32_t>(o.points.size());
    for (const auto& p : o.points) x.points.push_back({p.x(), p.y(), p.z()});
    x.num_volumes = static_cast<int32_t>(o.volumes.size());
    for (const PredictedVolumeOutput& v : o.volumes) {
      mbslam::predicted_volume_t pv{};
      pv.utime = v.utime;
      pv.horizon_us = v.horizon_us;
      for (int i = 0; i < 3; ++i) {
        pv.center[i] = v.center[i];
        pv.half_extent[i] = v.half_extent[i];
      }
      pv.orientation[0] = v.orientation.w();
      pv.orientation[1] = v.orientation.x();
      pv.orientation[2] = v.orientation.y();
      pv.orientation[3] = v.orientation.z();
      pv.probability = v.probability;
      x.volumes.push_back(pv);
    }
    m.objects.push_back(std::move(x));
  }
  return m;
}

mbslam::map_t ToLcm(const MapOutput& map) {
  mbslam::map_t m{};
  m.utime = map.utime;
  m.scale_state = static_cast<int8_t>(map.scale_state);
  m.num_points = static_cast<int32_t>(map.points.size());
  m.point_ids = map.point_ids;
  m.point_ids.resize(map.points.size(), 0);
  m.points.reserve(map.points.size());
  m.colors.reserve(map.points.size());
  for (size_t i = 0; i < map.points.size(); ++i) {
    const auto& p = map.points[i];
    m.points.push_back({p.x(), p.y(), p.z()});
    const std::array<uint8_t, 3> c = i < map.colors.size() ? map.colors[i] : std::array<uint8_t, 3>{128, 128, 128};
    m.colors.push_back({c[0], c[1], c[2]});
  }
  m.num_keyframes = static_cast<int32_t>(map.keyframes.size());
  for (const KeyframeOutput& k : map.keyframes) {
    mbslam::keyframe_t kf{};
    kf.id = k.id;
    kf.utime = k.utime;
    PutPose(k.world_from_cam, kf.position, kf.orientation);
    kf.num_observations = k.num_observations;
    m.keyframes.push_back(kf);
  }
  for (int i = 0; i < 4; ++i) m.ground_plane[i] = map.ground_plane[i];
  return m;
}

mbslam::occupancy_t ToLcm(const OccupancyOutput& o) {
  mbslam::occupancy_t m{};
  m.utime = o.utime;
  m.frame_id = "world";
  m.scale_state = static_cast<int8_t>(o.scale_state);
  m.resolution = o.resolution;
  m.num_occupied = o.num_occupied;
  m.memory_bytes = o.memory_bytes;
  m.size = static_cast<int32_t>(o.octree_binary.size());
  m.data.assign(o.octree_binary.begin(), o.octree_binary.end());
  return m;
}

mbslam::status_t ToLcm(const PipelineStatus& s) {
  mbslam::status_t m{};
  m.utime = s.utime;
  m.wall_utime = s.wall_utime;
  m.state = static_cast<int8_t>(s.state);
  m.message = s.message;
  m.mode = s.lockstep ? mbslam::status_t::MODE_LOCKSTEP : mbslam::status_t::MODE_REALTIME;
  m.frames_received = s.frames_received;
  m.frames_processed = s.frames_processed;
  m.frames_dropped = s.frames_dropped;
  m.frames_rejected = s.frames_rejected;
  m.input_fps = s.input_fps;
  m.processed_fps = s.processed_fps;
  m.latency_p50_ms = s.latency_p50_ms;
  m.latency_p99_ms = s.latency_p99_ms;
  m.memory_rss_bytes = s.memory.rss_bytes;
  m.heap_in_use_bytes = s.memory.heap_in_use_bytes;
  m.heap_held_bytes = s.memory.heap_held_bytes;
  m.results_kept_bytes = s.results_kept_bytes;
  m.num_stages = static_cast<int32_t>(s.stages.size());
  for (const StageStatus& st : s.stages) {
    mbslam::stage_timing_t t{};
    t.name = st.name;
    t.count = st.timing.count;
    t.mean_ms = st.timing.mean_ms;
    t.p50_ms = st.timing.p50_ms;
    t.p99_ms = st.timing.p99_ms;
    t.max_ms = st.timing.max_ms;
    t.overruns = st.timing.overruns;
    m.stages.push_back(t);
  }
  m.num_queues = static_cast<int32_t>(s.queues.size());
  for (const QueueStatus& q : s.queues) {
    mbslam::queue_status_t x{};
    x.name = q.name;
    x.depth = q.depth;
    x.capacity = q.capacity;
    x.dropped = q.dropped;
    m.queues.push_back(x);
  }
  m.num_counters = static_cast<int32_t>(s.counters.size());
  for (const auto& [name, value] : s.counters) {
    mbslam::counter_t c{};
    c.name = name;
    c.value = value;
    m.counters.push_back(c);
  }
  return m;
}

LcmOutputSink::LcmOutputSink(LcmBus* bus, LcmLogWriter* log, const ChannelOptions& channels,
                             bool publish_tracks)
    : bus_(bus), log_(log), channels_(channels), publish_tracks_(publish_tracks) {}

template <typename Msg>
void LcmOutputSink::Emit(const std::string& channel, int64_t utime, const Msg& msg) {
  if (bus_ != nullptr) bus_->Publish(channel, msg);
  if (log_ != nullptr) {
    std::lock_guard<std::mutex> lock(log_mutex_);
    const Status s = log_->Write(channel, utime, msg);
    if (!s.ok()) MBSLAM_LOG(ERROR) << "output log: " << s.message();
  }
}

void LcmOutputSink::OnFrameResult(const FrameResult& r) {
  Emit(channels_.perception_camera_pose, r.utime, ToLcm(r.camera_pose));
  Emit(channels_.perception_objects, r.utime, ToLcmObjects(r));
  if (publish_tracks_) Emit(channels_.perception_tracks, r.utime, ToLcmTracks(r));
  if (r.map) Emit(channels_.perception_map, r.utime, ToLcm(*r.map));
  if (r.occupancy) Emit(channels_.perception_occupancy, r.utime, ToLcm(*r.occupancy));
}

void LcmOutputSink::PublishStatus(const PipelineStatus& status) {
  if (bus_ != nullptr) bus_->Publish(channels_.perception_status, ToLcm(status));
}

}  // namespace mbslam
