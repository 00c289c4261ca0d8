#include "services/perception/pipeline/perception_core.h"

#include <algorithm>
#include <cmath>

#include <opencv2/video/tracking.hpp>

#include "common/util/logging.h"

namespace mbslam {

PerceptionCore::PerceptionCore(const CoreOptions& options, Counters* counters, StageTimers* timers)
    : options_(options),
      counters_(counters),
      preprocess_timer_(timers->Get("preprocess")),
      tracking_timer_(timers->Get("tracking")),
      segmentation_timer_(timers->Get("segmentation")),
      odometry_(options.preprocess.max_odometry_gap_us,
                static_cast<size_t>(options.preprocess.max_odometry_samples)),
      tracker_(options.tracking),
      segmenter_(options.segmentation),
      person_detector_(options.person) {
  const auto& q = options.odometry.base_from_cam_rotation;
  const auto& t = options.odometry.base_from_cam_translation;
  base_from_cam_ = Rigid3d(Eigen::Quaterniond(q[0], q[1], q[2], q[3]), Eigen::Vector3d(t[0], t[1], t[2]));
}

void PerceptionCore::Reset() {
  tracker_.Reset();
  segmenter_.Reset();
  odometry_.Clear();
  frame_utime_.clear();
  occluders_.clear();
  person_checked_.clear();
  is_person_.clear();
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

FrameResult PerceptionCore::ProcessFrame(const ImageFrame& frame) {
  if (frame.timeline_reset) {
    MBSLAM_LOG(WARNING) << "image time went back for good at " << frame.utime << ": starting over";
    Reset();
  }
  ++frame_index_;
  frame_utime_[frame_index_] = frame.utime;
  while (frame_utime_.size() > 64) frame_utime_.erase(frame_utime_.begin());

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
    cv::buildOpticalFlowPyramid(frame.gray, pyramid_, cv::Size(21, 21),
                                options_.preprocess.pyramid_levels - 1);
  }

  // Tracking, with the previous image's moving hulls as occluders (feedback from
  // segmentation).
  {
    ScopedStageTimer timer(tracking_timer_);
    TrackingHints hints;
    hints.occluders = occluders_;
    tracker_.TrackFrame(pyramid_, frame_index_, hints);
  }

  // Segmentation on the active tracks.
  SegmentationResult seg;
  {
    ScopedStageTimer timer(segmentation_timer_);
    const CameraIntrinsics& K = *frame.intrinsics;
    SegmenterInput in;
    in.frame_index = frame_index_;
    in.width = frame.gray.cols;
    in.height = frame.gray.rows;
    in.focal_px = 0.5 * (K.fx + K.fy);
    in.K = K.K();
    for (const Track& t : tracker_.tracks()) {
      if (!t.active()) continue;
      TrackObservation o;
      o.id = t.id;
      o.uv = t.uv.cast<double>();
      o.xy = K.PixelToNormalized(o.uv);
      in.observations.push_back(o);
    }
    in.world_motion = [this](int64_t r, int64_t n) { return OdometryMotion(r, n); };
    if (options_.odometry.use_for_ego_motion && !odometry_.empty()) {
      const double zmin = options_.odometry.min_depth_m;
      const double zmax = options_.odometry.max_depth_m > 0.0 ? options_.odometry.max_depth_m
                                                              : std::numeric_limits<double>::infinity();
      in.depth_bound = [zmin, zmax](int64_t, const Eigen::Vector2d&, int64_t) {
        return DepthBound{zmin, zmax};
      };
    }
    seg = segmenter_.Update(in);
  }
  if (GetLogLevel() <= LogLevel::kDebug) {
    int moving = 0;
    for (const TrackLabel& l : seg.labels) moving += l.body_id != 0;
    MBSLAM_LOG(DEBUG) << "frame " << frame_index_ << ": tracks " << seg.labels.size() << " moving "
                      << moving << " objects " << seg.objects.size() << " world motion "
                      << (seg.world_motion ? (seg.world_motion->translation_known ? "R,t" : "R only") : "none")
                      << " ref " << seg.world_ref_frame;
  }

  // Labels back onto the tracks (feedback to the tracker's occlusion handling).
  std::unordered_map<int64_t, const TrackLabel*> label_of;
  for (const TrackLabel& l : seg.labels) label_of[l.id] = &l;
  for (Track& t : tracker_.tracks()) {
    auto it = label_of.find(t.id);
    if (it == label_of.end()) continue;
    t.body_id = it->second->body_id;
    t.p_static = static_cast<float>(it->second->p_static);
  }

  // Moving objects: hulls, person check, occluders for the next image.
  occluders_.clear();
  for (const SegmentedObject& o : seg.objects) {
    ObjectOutput out;
    out.id = o.id;
    out.state = ObjectState::kDetected;
    auto [first, inserted] = object_first_utime_.try_emplace(o.id, frame.utime);
    out.first_seen_utime = first->second;
    out.num_tracks = static_cast<int>(o.track_ids.size());
    HullOutput hull;
    hull.body_id = o.id;
    TrackingHints::Hull occ;
    occ.body_id = o.id;
    float min_x = 1e9f, min_y = 1e9f, max_x = -1e9f, max_y = -1e9f;
    for (const Eigen::Vector2d& p : o.hull) {
      hull.points.push_back(p.cast<float>());
      occ.points.push_back((p + o.mean_flow_px).cast<float>());
      min_x = std::min(min_x, static_cast<float>(p.x()));
      min_y = std::min(min_y, static_cast<float>(p.y()));
      max_x = std::max(max_x, static_cast<float>(p.x()));
      max_y = std::max(max_y, static_cast<float>(p.y()));
    }
    if (options_.person.enabled && hull.points.size() >= 3) {
      auto last = person_checked_.find(o.id);
      if (last == person_checked_.end() || frame_index_ - last->second >= options_.person.every_n_frames) {
        const cv::Rect box(static_cast<int>(min_x), static_cast<int>(min_y),
                           static_cast<int>(max_x - min_x), static_cast<int>(max_y - min_y));
        if (person_detector_.Detect(frame.gray, box)) is_person_[o.id] = true;
        person_checked_[o.id] = frame_index_;
      }
    }
    out.object_class = is_person_[o.id] ? ObjectClass::kPerson : ObjectClass::kUnknown;
    out.hull = hull;
    result.hulls.push_back(hull);
    if (occ.points.size() >= 3) occluders_.push_back(std::move(occ));
    result.objects.push_back(std::move(out));
  }
  result.epipole = seg.epipole;

  for (const Track& t : tracker_.tracks()) {
    TrackOutput o;
    o.id = t.id;
    o.uv = t.uv;
    o.prev_uv = t.is_new ? Eigen::Vector2f::Constant(NAN) : t.prev_uv;
    o.age = t.age;
    o.body_id = t.body_id;
    o.p_static = t.p_static;
    o.occluded = !t.active();
    o.has_3d = t.has_3d;
    o.is_new = t.is_new;
    auto it = label_of.find(t.id);
    if (it != label_of.end()) {
      o.epipolar_px = static_cast<float>(it->second->epipolar_px);
      o.fvb = static_cast<float>(it->second->p_fvb);
    }
    result.tracks.push_back(o);
  }
  if (seg.initialized) result.camera_pose.tracking_state = TrackingState::kInitializing;
  return result;
}

}  // namespace mbslam
