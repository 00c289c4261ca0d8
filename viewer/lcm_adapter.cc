#include "viewer/lcm_adapter.h"

#include <cmath>
#include <utility>

#include "common/lcm/wire_check.h"
#include "common/util/logging.h"

namespace mbslam {
namespace viewer {
namespace {

static_assert(static_cast<int>(TrackingState::kNotInitialized) ==
              mbslam::camera_pose_t::TRACKING_NOT_INITIALIZED);
static_assert(static_cast<int>(TrackingState::kInitializing) ==
              mbslam::camera_pose_t::TRACKING_INITIALIZING);
static_assert(static_cast<int>(TrackingState::kOk) == mbslam::camera_pose_t::TRACKING_OK);
static_assert(static_cast<int>(TrackingState::kLost) == mbslam::camera_pose_t::TRACKING_LOST);
static_assert(static_cast<int>(TrackingState::kRelocalized) ==
              mbslam::camera_pose_t::TRACKING_RELOCALIZED);
static_assert(static_cast<int>(ObjectState::kDetected) == mbslam::object_t::STATE_DETECTED);
static_assert(static_cast<int>(ObjectState::kTracked) == mbslam::object_t::STATE_TRACKED);
static_assert(static_cast<int>(ObjectState::kReconstructed) ==
              mbslam::object_t::STATE_RECONSTRUCTED);
static_assert(static_cast<int>(ImageEncoding::kGray8) == mbslam::image_t::ENCODING_GRAY8);
static_assert(static_cast<int>(ImageEncoding::kRgb8) == mbslam::image_t::ENCODING_RGB8);
static_assert(static_cast<int>(ImageEncoding::kBgr8) == mbslam::image_t::ENCODING_BGR8);
static_assert(static_cast<int>(ImageEncoding::kJpeg) == mbslam::image_t::ENCODING_JPEG);
static_assert(static_cast<int>(ImageEncoding::kPng) == mbslam::image_t::ENCODING_PNG);

Eigen::Vector3d Vec3(const double v[3]) { return Eigen::Vector3d(v[0], v[1], v[2]); }

// [w, x, y, z] -> Eigen; false when it cannot be a rotation.
bool Quaternion(const double q[4], Eigen::Quaterniond* out) {
  const Eigen::Quaterniond r(q[0], q[1], q[2], q[3]);
  if (!r.coeffs().allFinite() || r.norm() < 1e-6) return false;
  *out = r.normalized();
  return true;
}

Eigen::Vector3f Point3(const std::vector<float>& p) {
  return p.size() == 3 ? Eigen::Vector3f(p[0], p[1], p[2])
                       : Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
}

bool Metric(int8_t scale_state) { return scale_state == mbslam::camera_pose_t::SCALE_METRIC; }

}  // namespace

Status FromLcm(const mbslam::camera_pose_t& m, CameraPoseSample* out) {
  out->utime = m.utime;
  out->world_from_cam.position = Vec3(m.position);
  if (!out->world_from_cam.position.allFinite()) return Status::Error("non-finite camera position");
  if (!Quaternion(m.orientation, &out->world_from_cam.orientation)) {
    return Status::Error("camera orientation is not a rotation");
  }
  if (m.tracking_state < 0 || m.tracking_state > mbslam::camera_pose_t::TRACKING_RELOCALIZED) {
    return Status::Error("unknown tracking state " + std::to_string(m.tracking_state));
  }
  out->tracking_state = static_cast<TrackingState>(m.tracking_state);
  out->metric = Metric(m.scale_state);
  return Status::Ok();
}

Status FromLcm(const mbslam::map_t& m, MapData* out) {
  out->utime = m.utime;
  out->metric = Metric(m.scale_state);
  out->points.reserve(m.points.size());
  for (const auto& p : m.points) out->points.push_back(Point3(p));
  if (m.colors.size() == m.points.size()) {
    out->colors.reserve(m.colors.size());
    for (const auto& c : m.colors) {
      out->colors.push_back(c.size() == 3 ? std::array<uint8_t, 3>{c[0], c[1], c[2]}
                                          : std::array<uint8_t, 3>{128, 128, 128});
    }
  }
  for (const auto& kf : m.keyframes) {
    KeyframeData k;
    k.id = kf.id;
    k.world_from_cam.position = Vec3(kf.position);
    if (!k.world_from_cam.position.allFinite() ||
        !Quaternion(kf.orientation, &k.world_from_cam.orientation)) {
      continue;  // one bad keyframe does not spoil the map
    }
    out->keyframes.push_back(k);
  }
  const Eigen::Vector4d plane(m.ground_plane[0], m.ground_plane[1], m.ground_plane[2],
                              m.ground_plane[3]);
  if (plane.allFinite() && plane.head<3>().norm() > 0.5) out->ground_plane = plane;
  return Status::Ok();
}

Status FromLcm(const mbslam::objects_t& m, ObjectsData* out) {
  out->utime = m.utime;
  out->metric = Metric(m.scale_state);
  for (const auto& o : m.objects) {
    ObjectData d;
    d.id = o.id;
    d.state = o.state >= 0 && o.state <= mbslam::object_t::STATE_RECONSTRUCTED
                  ? static_cast<ObjectState>(o.state)
                  : ObjectState::kDetected;
    d.position = Vec3(o.position);
    d.linear_velocity = Vec3(o.linear_velocity);
    for (const auto& p : o.particle_samples) d.particles.push_back(Point3(p));
    for (const auto& p : o.points) d.points.push_back(Point3(p));
    for (const auto& v : o.volumes) {
      OrientedBox b;
      b.utime = v.utime;
      b.horizon_us = v.horizon_us;
      b.center = Vec3(v.center);
      b.half_extent = Vec3(v.half_extent);
      b.probability = v.probability;
      if (!Quaternion(v.orientation, &b.world_from_box)) continue;
      d.volumes.push_back(b);
    }
    out->objects.push_back(std::move(d));
  }
  return Status::Ok();
}

Status FromLcm(const mbslam::occupancy_t& m, EncodedOccupancy* out) {
  out->utime = m.utime;
  out->metric = Metric(m.scale_state);
  out->resolution = m.resolution;
  out->data = m.data;
  return Status::Ok();
}

Status FromLcm(const mbslam::tracks_t& m, TracksData* out) {
  out->utime = m.utime;
  out->frame_seq = m.frame_seq;
  out->width = std::max(0, m.width);
  out->height = std::max(0, m.height);
  out->epipole = Vec3(m.epipole);
  if (!out->epipole.allFinite()) out->epipole.setZero();
  out->tracks.reserve(m.tracks.size());
  for (const auto& t : m.tracks) {
    TrackFeature f;
    f.id = t.id;
    f.u = t.u;
    f.v = t.v;
    f.prev_u = t.prev_u;
    f.prev_v = t.prev_v;
    f.body_id = t.body_id;
    f.p_static = t.p_static;
    f.epipolar_px = t.epipolar_px;
    f.occluded = (t.flags & mbslam::feature_track_t::FLAG_OCCLUDED) != 0;
    f.is_new = (t.flags & mbslam::feature_track_t::FLAG_NEW) != 0;
    out->tracks.push_back(f);
  }
  for (const auto& h : m.hulls) {
    ImageHull hull;
    hull.body_id = h.body_id;
    if (h.u.size() != h.v.size()) return Status::Error("hull with unequal u and v arrays");
    for (size_t i = 0; i < h.u.size(); ++i) hull.points.emplace_back(h.u[i], h.v[i]);
    out->hulls.push_back(std::move(hull));
  }
  return Status::Ok();
}

Status FromLcm(mbslam::image_t&& m, EncodedImage* out) {
  if (m.encoding < mbslam::image_t::ENCODING_GRAY8 || m.encoding > mbslam::image_t::ENCODING_PNG) {
    return Status::Error("unknown image encoding " + std::to_string(m.encoding));
  }
  out->utime = m.utime;
  out->width = m.width;
  out->height = m.height;
  out->row_stride = m.row_stride;
  out->encoding = static_cast<ImageEncoding>(m.encoding);
  out->data = std::move(m.data);
  return Status::Ok();
}

ViewerLcmAdapter::ViewerLcmAdapter(LcmBus* bus, const ChannelOptions& channels, int queue_capacity,
                                   size_t max_message_bytes, SceneState* scene)
    : scene_(scene), max_message_bytes_(max_message_bytes) {
  auto subscribe = [&](const std::string& channel, LcmBus::RawHandler handler) {
    counts_[channel];
    bus->Subscribe(channel, std::move(handler), queue_capacity);
  };
  subscribe(channels.perception_camera_pose,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::camera_pose_t m{};
              if (!Decode(ch, data, size, &m)) return;
              CameraPoseSample pose;
              const Status s = FromLcm(m, &pose);
              if (!s.ok()) return Bad(ch, s.message());
              BeforeMessage(pose.utime);
              scene_->AddCameraPose(pose);
            });
  subscribe(channels.perception_map,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::map_t m{};
              if (!Decode(ch, data, size, &m)) return;
              MapData map;
              const Status s = FromLcm(m, &map);
              if (!s.ok()) return Bad(ch, s.message());
              BeforeMessage(map.utime);
              scene_->SetMap(std::move(map));
            });
  subscribe(channels.perception_objects,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::objects_t m{};
              if (!Decode(ch, data, size, &m)) return;
              ObjectsData objects;
              const Status s = FromLcm(m, &objects);
              if (!s.ok()) return Bad(ch, s.message());
              BeforeMessage(objects.utime);
              scene_->SetObjects(std::move(objects));
            });
  subscribe(channels.perception_occupancy,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::occupancy_t m{};
              if (!Decode(ch, data, size, &m)) return;
              EncodedOccupancy occupancy;
              const Status s = FromLcm(m, &occupancy);
              if (!s.ok()) return Bad(ch, s.message());
              BeforeMessage(occupancy.utime);
              scene_->SetOccupancy(std::move(occupancy));
            });
  subscribe(channels.perception_tracks,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::tracks_t m{};
              if (!Decode(ch, data, size, &m)) return;
              TracksData tracks;
              const Status s = FromLcm(m, &tracks);
              if (!s.ok()) return Bad(ch, s.message());
              BeforeMessage(tracks.utime);
              scene_->AddTracks(std::move(tracks));
            });
  subscribe(channels.camera_image,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::image_t m{};
              if (!Decode(ch, data, size, &m)) return;
              EncodedImage image;
              const Status s = FromLcm(std::move(m), &image);
              if (!s.ok()) return Bad(ch, s.message());
              BeforeMessage(image.utime);
              scene_->AddImage(std::move(image));
            });
  subscribe(channels.snapshot_request,
            [this](const std::string& ch, const uint8_t* data, size_t size, int64_t) {
              mbslam::snapshot_request_t m{};
              if (!Decode(ch, data, size, &m)) return;
              if (snapshot_hook_) snapshot_hook_(m.what, m.path_prefix);
            });
}

template <typename Msg>
bool ViewerLcmAdapter::Decode(const std::string& channel, const uint8_t* data, size_t size,
                              Msg* msg) {
  ++counts_[channel].received;
  const Status s = DecodeLcmMessage(data, size, msg, max_message_bytes_);
  if (!s.ok()) {
    Bad(channel, s.message());
    return false;
  }
  return true;
}

void ViewerLcmAdapter::Bad(const std::string& channel, const std::string& why) {
  ChannelCounts& c = counts_[channel];
  ++c.bad;
  c.last_error = why;
  // The first few of each channel are logged, then one in a hundred.
  if (c.bad <= 5 || c.bad % 100 == 0) {
    MBSLAM_LOG(WARNING) << "viewer: bad message #" << c.bad << " on " << channel << ": " << why;
  }
}

void ViewerLcmAdapter::BeforeMessage(int64_t utime) {
  if (time_hook_) time_hook_(utime);
}

int64_t ViewerLcmAdapter::bad_total() const {
  int64_t n = 0;
  for (const auto& [channel, c] : counts_) n += c.bad;
  return n;
}

int64_t ViewerLcmAdapter::received_total() const {
  int64_t n = 0;
  for (const auto& [channel, c] : counts_) n += c.received;
  return n;
}

}  // namespace viewer
}  // namespace mbslam
