#include "services/perception/slam/slam_system.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <sstream>
#include <unordered_set>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "common/util/logging.h"
#include "common/util/statistics.h"
#include "services/perception/geometry/polygon.h"
#include "services/perception/slam/init_selection.h"
#include "services/perception/slam/triangulation.h"
#include "services/perception/tracking/orb_features.h"
#include "services/perception/tracking/patch_matcher.h"

namespace mbslam {
namespace {

constexpr double kDeg = M_PI / 180.0;
// Grid of the initialisation's coverage test (cells across, down).
constexpr int kInitGridCols = 8;
constexpr int kInitGridRows = 6;
// A track released as a pose outlier and unseen by this SLAM for this long is forgotten
// (frames): it has ended, or left the object's segment long ago. Only bounds the memory:
// track ids are never reused.
constexpr int64_t kReleasedTrackMemoryFrames = 300;

// A free essential matrix between normalised correspondences (RANSAC, inlier threshold
// `thresh` in normalised units), with the correspondences as OpenCV points.
struct EssentialFit {
  std::vector<cv::Point2d> pr, pn;
  cv::Mat E;     // empty (or not 3 rows) when none was found
  cv::Mat mask;  // inliers
  int inliers = 0;
  bool ok() const { return !E.empty() && E.rows == 3; }
};

EssentialFit FitEssential(const std::vector<Eigen::Vector2d>& xr, const std::vector<Eigen::Vector2d>& xn,
                          double thresh) {
  EssentialFit fit;
  fit.pr.resize(xr.size());
  fit.pn.resize(xn.size());
  for (size_t i = 0; i < xr.size(); ++i) {
    fit.pr[i] = cv::Point2d(xr[i].x(), xr[i].y());
    fit.pn[i] = cv::Point2d(xn[i].x(), xn[i].y());
  }
  fit.E = cv::findEssentialMat(fit.pr, fit.pn, 1.0, cv::Point2d(0, 0), cv::RANSAC, 0.999, thresh, fit.mask);
  if (fit.ok()) fit.inliers = cv::countNonZero(fit.mask);
  return fit;
}

}  // namespace

const char* SlamStateName(SlamState state) {
  switch (state) {
    case SlamState::kNotInitialized: return "not_initialized";
    case SlamState::kInitializing: return "initializing";
    case SlamState::kConfirming: return "confirming";
    case SlamState::kTracking: return "tracking";
    case SlamState::kLost: return "lost";
  }
  return "unknown";
}

SlamSystem::SlamSystem(const SlamOptions& options, std::string log_name)
    : options_(options), log_name_(std::move(log_name)) {
  if (!options_.map_load_path.empty()) {
    const Status s = LoadMap(options_.map_load_path);
    if (!s.ok()) MBSLAM_LOG(WARNING) << "map not loaded: " << s.message();
  }
}

SlamSystem::~SlamSystem() {
  Flush();
  const bool any_map = map_.num_keyframes() > 0 ||
                       std::any_of(lost_maps_.begin(), lost_maps_.end(),
                                   [](const LostMap& m) { return m.map.num_keyframes() > 0; });
  if (!options_.map_save_path.empty() && any_map) {
    const Status s = SaveMap(options_.map_save_path);
    if (!s.ok()) MBSLAM_LOG(ERROR) << "map not saved: " << s.message();
  }
}

void SlamSystem::Flush() { MergeBundleAdjustment(/*wait=*/true); }

void SlamSystem::Reset() {
  Flush();
  ResolveTrajectory();
  refine_obs_.clear();
  ++map_generation_;
  bridge_.reset();
  map_.Clear();
  state_ = SlamState::kNotInitialized;
  init_ref_frame_ = -1;
  init_pending_frame_ = -1;
  init_pending_pair_.reset();
  init_ref_xy_.clear();
  init_ref_odom_.reset();
  init_ref_rotation_prior_.reset();
  rotation_prior_active_ = false;
  recent_poses_.clear();
  lost_frames_ = 0;
  metric_ = false;
  confirm_count_ = 0;
  unposed_.clear();
  posed_xy_.clear();
  hybrid_frames_ = 0;
  released_tracks_.clear();
  ground_plane_.reset();
  awaiting_loaded_map_ = false;
  relocalized_map_ = false;
  map_serial_ = next_map_serial_++;
  last_lost_map_search_ = -1;
}

void SlamSystem::KeepLostMap() {
  if (!options_.relocalization || options_.lost_maps_kept <= 0 || map_.num_keyframes() == 0) return;
  const size_t described = map_.num_described_points();
  if (described < static_cast<size_t>(options_.reloc_min_inliers)) return;
  LostMap lost;
  ResolveTrajectory();  // the entries anchored on its keyframes, before the map leaves
  lost.map = map_;
  // Its tracks are this run's past: the tracks that come back to it are given again by
  // relocalisation (a track id may have moved on to another corner since).
  // Nor is what hid its points then still in front of them.
  for (auto& [id, p] : lost.map.points()) {
    if (p.track_id >= 0) lost.map.ReleaseTrack(p.track_id);
    p.occluded = false;
  }
  lost.serial = map_serial_;
  lost.metric = metric_;
  lost.ground_plane = ground_plane_;
  MBSLAM_LOG(INFO) << log_name_ << ": map " << lost.serial << " kept to relocalise in later ("
                   << lost.map.num_keyframes() << " keyframes, " << described
                   << " described points)";
  lost_maps_.push_back(std::move(lost));
  std::sort(lost_maps_.begin(), lost_maps_.end(),
            [](const LostMap& a, const LostMap& b) { return a.serial < b.serial; });
  while (static_cast<int>(lost_maps_.size()) > options_.lost_maps_kept) {
    // The newest go first: the oldest is the frame the later maps were bridged to.
    const size_t drop = lost_maps_.size() > 1 ? lost_maps_.size() - 1 : 0;
    MBSLAM_LOG(INFO) << log_name_ << ": kept map " << lost_maps_[drop].serial << " dropped";
    lost_maps_.erase(lost_maps_.begin() + static_cast<std::ptrdiff_t>(drop));
  }
}

bool SlamSystem::RejoinLostMap(const SlamFrame& frame) {
  rejoin_placement_.reset();
  if (lost_maps_.empty() || !options_.relocalization || !frame.intrinsics || frame.image.empty()) {
    return false;
  }
  const bool initializing =
      state_ == SlamState::kNotInitialized || state_ == SlamState::kInitializing;
  const bool tracking = state_ == SlamState::kTracking;
  if (!initializing && !tracking) return false;
  if (tracking) {
    if (last_lost_map_search_ >= 0 &&
        frame.frame_index - last_lost_map_search_ < options_.lost_map_search_frames) {
      return false;
    }
    last_lost_map_search_ = frame.frame_index;
  }
  const int min_inliers = tracking ? options_.lost_map_min_inliers : options_.reloc_min_inliers;
  for (size_t i = 0; i < lost_maps_.size(); ++i) {
    LostMap& lost = lost_maps_[i];
    if (tracking && lost.serial >= map_serial_) continue;  // only older maps replace it
    Placement placed;
    placed.frame_index = frame.frame_index;
    if (!Relocalize(frame, &lost.map, min_inliers, "kept map " + std::to_string(lost.serial),
                    &placed.X, &placed.xy, &placed.tracks, &placed.patches, &placed.refound_ids,
                    &placed.refound_uv, &placed.est)) {
      continue;
    }
    LostMap back = std::move(lost);
    lost_maps_.erase(lost_maps_.begin() + static_cast<std::ptrdiff_t>(i));
    MBSLAM_LOG(INFO) << log_name_ << " frame " << frame.frame_index << ": kept map " << back.serial
                     << " placed the image ("
                     << (tracking ? "it replaces map " + std::to_string(map_serial_)
                                  : std::string("re-initialising"))
                     << "): it is taken up again";
    // The current map is kept in turn (a tracking one; an initialisation has none yet).
    // The images not posed meanwhile stay so: their tracks hold no point of it.
    MergeBundleAdjustment(/*wait=*/true);
    if (tracking) KeepLostMap();
    Reset();
    map_ = std::move(back.map);
    map_serial_ = back.serial;
    metric_ = back.metric;
    ground_plane_ = back.ground_plane;
    // Its keyframes hold none of the tracks: its next keyframe comes keyframe_min_frames
    // after this image (the tracked count of none is passed at once), once the re-found
    // points have tracks. At this image itself (its last keyframe's age) it held only
    // the few re-found tracks: TartanAir entering a map, 0.31 m in its frame after,
    // against 0.16 m.
    last_keyframe_frame_ = frame.frame_index;
    tracked_points_at_keyframe_ = std::numeric_limits<int>::max() / 2;
    state_ = SlamState::kLost;  // the tracking that follows is placed by this relocalisation
    rejoin_placement_ = std::move(placed);
    ++maps_rejoined_;
    return true;
  }
  return false;
}

std::optional<double> CameraHeightAboveGround(const std::vector<Eigen::Vector3d>& points_in_cam,
                                              const Eigen::Vector3d& up_in_cam, double band,
                                              int min_points, double min_share) {
  std::vector<double> below;  // heights of the points below the camera
  for (const Eigen::Vector3d& p : points_in_cam) {
    const double h = -up_in_cam.dot(p);
    if (h > 0.0 && std::isfinite(h)) below.push_back(h);
  }
  std::sort(below.begin(), below.end());
  const auto window = [&](double h) {
    return std::make_pair(std::lower_bound(below.begin(), below.end(), h * (1.0 - band)),
                          std::upper_bound(below.begin(), below.end(), h * (1.0 + band)));
  };
  const double need =
      std::max(static_cast<double>(min_points), min_share * static_cast<double>(below.size()));
  // The lowest surface: the largest height whose window holds enough points.
  std::optional<double> start;
  for (double h : below) {
    const auto [lo, hi] = window(h);
    if (static_cast<double>(hi - lo) >= need) start = h;
  }
  if (!start) return std::nullopt;
  // That window lies on the far side of the surface's spread: the mean of the points
  // around the height, repeated until it settles, is its middle.
  double h = *start;
  for (int iter = 0; iter < 50; ++iter) {
    const auto [lo, hi] = window(h);
    if (lo == hi) break;
    double sum = 0.0;
    for (auto it = lo; it != hi; ++it) sum += *it;
    const double next = sum / static_cast<double>(hi - lo);
    const bool settled = std::abs(next - h) <= 1e-9 * h;
    h = next;
    if (settled) break;
  }
  return h;
}

bool GroundLengthIsUsable(const GroundLengthEstimate& g, const SlamOptions& options) {
  return g.ok && g.support >= options.hybrid_ground_min_links &&
         g.support >= options.hybrid_ground_min_share * static_cast<double>(g.candidates) &&
         std::max(g.support_shorter, g.support_longer) <=
             options.hybrid_ground_step_max_support * static_cast<double>(g.support);
}

void SlamSystem::SetGroundPlane(const Eigen::Vector4d& plane) {
  if (!plane.allFinite() || !(std::abs(plane.head<3>().norm() - 1.0) < 1e-6)) return;
  ground_plane_ = plane;
}

void SlamSystem::RestartMap(std::optional<Bridge> bridge) {
  auto unposed = std::move(unposed_);
  Reset();
  bridge_ = std::move(bridge);
  unposed_ = std::move(unposed);
}

Status SlamSystem::SaveMap(const std::string& path) {
  Flush();
  // The largest map (keyframes): the current one, or a kept one when the current map is
  // smaller (a run that lost its map near the end saves the map it had).
  const Map* largest = &map_;
  for (const LostMap& lost : lost_maps_) {
    if (lost.map.num_keyframes() > largest->num_keyframes()) largest = &lost.map;
  }
  if (largest->num_keyframes() == 0) return Status::Error("no map to save");
  if (largest == &map_ && options_.map_save_global_ba && map_.num_keyframes() >= 2) {
    const int64_t runs = ba_runs_;
    StartBundleAdjustment(/*global=*/true, /*requested=*/true, /*here_and_now=*/true);
    MBSLAM_LOG(INFO) << log_name_ << ": the map saved was first adjusted as a whole ("
                     << map_.num_keyframes() << " keyframes, " << last_ba_seconds_ << " s, "
                     << (ba_runs_ > runs && last_ba_usable_ ? "used" : "not used") << ")";
  }
  if (largest != &map_) {
    MBSLAM_LOG(INFO) << log_name_ << ": the map saved is a kept one (" << largest->num_keyframes()
                     << " keyframes; the current map has " << map_.num_keyframes() << ")";
  }
  return largest->Save(path);
}

Status SlamSystem::LoadMap(const std::string& path) {
  Flush();
  Map loaded;
  MBSLAM_RETURN_IF_ERROR(loaded.Load(path));
  ResolveTrajectory();  // the loaded map's keyframe and point ids start again
  Reset();
  refine_obs_.clear();
  // The saving run's image numbers mean nothing in this run, which counts from its own
  // first image: the keyframes are moved before it (the trajectory files' "a keyframe's
  // image is the keyframe" and back-fill's nearest keyframe compare them with this run's).
  int64_t newest = 0;
  for (const auto& [id, k] : loaded.keyframes()) newest = std::max(newest, k.frame_index);
  for (auto& [id, k] : loaded.keyframes()) k.frame_index -= newest + 2;
  map_ = std::move(loaded);
  const size_t described = map_.num_described_points();
  // A loaded map is only trusted once the camera relocalises in it: until then the
  // service is lost in it (relocalisation) for at most reloc_loaded_max_frames images.
  // Without descriptors (an older file) it cannot relocalise: the first initialisation
  // replaces it.
  const bool relocalizable =
      options_.relocalization && described >= static_cast<size_t>(options_.reloc_min_inliers);
  state_ = relocalizable ? SlamState::kLost : SlamState::kNotInitialized;
  awaiting_loaded_map_ = relocalizable;
  MBSLAM_LOG(INFO) << log_name_ << ": map loaded: " << map_.num_keyframes() << " keyframes, "
                   << map_.num_points() << " points (" << described << " with descriptors)"
                   << (relocalizable
                           ? "; waiting for the camera to relocalise in it"
                           : "; it cannot be relocalised in, the first initialisation replaces it");
  return Status::Ok();
}

void SlamSystem::StorePose(int64_t frame, const Rigid3d& T, const Matrix6d& covariance, bool epipolar_assisted) {
  FramePose p;
  p.cam_from_world = T;
  p.covariance = covariance;
  p.epipolar_assisted = epipolar_assisted;
  if (const Keyframe* kf = map_.LastKeyframe()) {
    p.anchor_keyframe = kf->id;
    p.cam_from_anchor = T * kf->cam_from_world.Inverse();
  }
  recent_poses_[frame] = p;
  while (recent_poses_.size() > 64) recent_poses_.erase(recent_poses_.begin());
}

void SlamSystem::RecordTrajectory(int64_t frame, const Rigid3d& T, const Keyframe* anchor) {
  if (options_.adjusted_trajectory_max_poses <= 0) return;
  auto u = frame_utime_.find(frame);
  if (u == frame_utime_.end()) {
    MBSLAM_LOG(WARNING) << log_name_ << ": the pose of image " << frame
                        << " is left out of the trajectory file: its time is no longer kept";
    return;
  }
  TrajectoryEntry e;
  e.frame = frame;
  e.utime = u->second;
  e.cam_from_world = T;
  if (anchor) {
    e.anchor_keyframe = anchor->id;
    e.cam_from_anchor = T * anchor->cam_from_world.Inverse();
  }
  trajectory_.push_back(e);
  if (static_cast<int>(trajectory_.size()) > options_.adjusted_trajectory_max_poses) {
    while (static_cast<int>(trajectory_.size()) > options_.adjusted_trajectory_max_poses) trajectory_.pop_front();
    // Culled keyframes older than the oldest entry's anchor are no longer needed (an entry
    // whose anchor is gone falls back to its pose as tracked).
    const int64_t oldest = trajectory_.front().anchor_keyframe;
    if (oldest >= 0) retired_keyframes_.erase(retired_keyframes_.begin(), retired_keyframes_.lower_bound(oldest));
  }
}

const Rigid3d* SlamSystem::AnchorPose(int64_t keyframe_id) const {
  if (keyframe_id < 0) return nullptr;
  if (const Keyframe* kf = map_.keyframe(keyframe_id)) return &kf->cam_from_world;
  auto r = retired_keyframes_.find(keyframe_id);
  return r != retired_keyframes_.end() ? &r->second : nullptr;
}

void SlamSystem::ResolveTrajectory() {
  for (TrajectoryEntry& e : trajectory_) {
    if (e.anchor_keyframe < 0) continue;
    if (const Rigid3d* K = AnchorPose(e.anchor_keyframe)) e.cam_from_world = e.cam_from_anchor * *K;
    e.anchor_keyframe = -1;
  }
  retired_keyframes_.clear();
}

void SlamSystem::RefineTrajectory() {
  if (refine_obs_.empty() || options_.adjusted_trajectory_refine_keyframes <= 0) return;
  std::set<int64_t> newest;
  int64_t oldest_frame = std::numeric_limits<int64_t>::max();
  for (auto k = map_.keyframes().rbegin();
       k != map_.keyframes().rend() && static_cast<int>(newest.size()) < options_.adjusted_trajectory_refine_keyframes;
       ++k) {
    newest.insert(k->first);
    oldest_frame = std::min(oldest_frame, k->second.frame_index);
  }
  // Images tracked before the oldest of them are done with.
  refine_obs_.erase(refine_obs_.begin(), refine_obs_.lower_bound(oldest_frame));
  if (refine_obs_.empty()) return;
  const int64_t first = refine_obs_.begin()->first;
  for (auto e = trajectory_.rbegin(); e != trajectory_.rend() && e->frame >= first; ++e) {
    auto o = refine_obs_.find(e->frame);
    if (o == refine_obs_.end() || !newest.count(e->anchor_keyframe)) continue;
    const Keyframe* kf = map_.keyframe(e->anchor_keyframe);
    if (!kf || kf->frame_index == e->frame) continue;  // a keyframe's image is the keyframe
    std::vector<Eigen::Vector3d> X;
    std::vector<Eigen::Vector2d> xy;
    for (const auto& [pid, x] : o->second.inliers) {
      const MapPoint* p = map_.point(pid);
      if (!p) continue;
      // A point whose track was released after this image (the segmentation stopped
      // calling it static, or the track drifted off it) was seen here through that
      // track: on sim-multi these are mostly the walkers' tracks a keyframe triangulated
      // while they still looked static, which pulled the images after it by up to 12 mm.
      // Sightings after the release (re-found by guided matching) are kept.
      if (options_.adjusted_trajectory_skip_released && p->released_frame >= e->frame) {
        ++refine_stats_.released_skipped;
        continue;
      }
      X.push_back(p->position);
      xy.push_back(x);
    }
    if (static_cast<int>(X.size()) < options_.min_tracking_inliers) continue;
    const Rigid3d T0 = e->cam_from_anchor * kf->cam_from_world;
    // Tracks triangulated since: gated on the image's current pose (a track that was
    // static then and has a point now is most likely static, but a wrong point must not
    // pull the pose).
    const double gate = options_.adjusted_trajectory_later_points_px / focal_px_;
    for (const auto& [track, x] : o->second.later) {
      const int64_t pid = map_.PointOfTrack(track);
      const MapPoint* p = pid >= 0 ? map_.point(pid) : nullptr;
      if (!p) continue;
      if (ReprojectionError(T0, p->position, x) > gate) {
        ++refine_stats_.later_gated;
        continue;
      }
      X.push_back(p->position);
      xy.push_back(x);
      ++refine_stats_.later_used;
    }
    ++refine_stats_.images;
    const std::vector<uint8_t> use(X.size(), 1);
    const Rigid3d T = RefinePose(T0, X, xy, use, focal_px_, options_.pose.huber_px,
                                 options_.pose.refine_iterations, nullptr);
    if (!T.translation.allFinite() || !T.rotation.coeffs().allFinite()) continue;
    e->cam_from_anchor = T * kf->cam_from_world.Inverse();
  }
}

std::vector<std::pair<int64_t, Rigid3d>> SlamSystem::AdjustedTrajectory() const {
  std::map<int64_t, Rigid3d> by_utime;
  for (const TrajectoryEntry& e : trajectory_) {
    const Rigid3d* K = AnchorPose(e.anchor_keyframe);
    by_utime[e.utime] = K ? e.cam_from_anchor * *K : e.cam_from_world;
  }
  return {by_utime.begin(), by_utime.end()};
}

std::optional<Rigid3d> SlamSystem::PoseOf(int64_t frame) const {
  auto it = recent_poses_.find(frame);
  if (it == recent_poses_.end()) return std::nullopt;
  if (const Keyframe* kf = map_.keyframe(it->second.anchor_keyframe)) {
    return it->second.cam_from_anchor * kf->cam_from_world;
  }
  return it->second.cam_from_world;
}

void SlamSystem::FindUntrackedPoints(const SlamFrame& frame, const Rigid3d& T,
                                     std::vector<int64_t>* point_ids, std::vector<Eigen::Vector2d>* xy,
                                     std::vector<Eigen::Vector2f>* uv) {
  const CameraIntrinsics& K = *frame.intrinsics;
  std::set<int64_t> candidates;
  int kfs = 0;
  for (auto it = map_.keyframes().rbegin(); it != map_.keyframes().rend() && kfs < options_.guided_keyframes;
       ++it, ++kfs) {
    candidates.insert(it->second.point_ids.begin(), it->second.point_ids.end());
  }
  if (relocalized_map_) {
    for (int64_t kid : NearestKeyframes(T, options_.guided_keyframes)) {
      const Keyframe* k = map_.keyframe(kid);
      candidates.insert(k->point_ids.begin(), k->point_ids.end());
    }
  }
  // For the debug log only: the held points whose tracks are no longer active (the
  // tracker does not report a track's end to the map; see below).
  std::unordered_set<int64_t> active;
  const bool debug = GetLogLevel() <= LogLevel::kDebug;
  if (debug) {
    for (const SlamObservation& o : frame.observations) active.insert(o.track_id);
  }
  const int margin = options_.guided_radius_px + 8;
  int searched = 0, tracked = 0, ended = 0, outside = 0, ambiguous = 0, unlike = 0;
  for (int64_t pid : candidates) {
    if (searched >= options_.guided_max_points) break;
    const MapPoint* p = map_.point(pid);
    if (!p || p->occluded || p->patch.empty()) continue;
    // Held by a track. That track may have ended (the tracker does not report a track's
    // end to the map); searching such points as well (only tracks observed in the image
    // hold their points) was measured and not kept: sim-multi ATE 0.240 -> 0.207 %, but
    // without segmentation feedback 0.737 -> 0.307 % (the ablation no longer 3x), and
    // TartanAir's mean ATE over five starts 1.09 -> 1.73 %.
    if (p->track_id >= 0) {
      ++tracked;
      if (debug && !active.count(p->track_id)) ++ended;
      continue;
    }
    const Eigen::Vector3d pc = T * p->position;
    if (pc.z() <= 1e-6) continue;
    const Eigen::Vector2d pred = K.Project(pc);
    if (!K.InImage(pred, margin)) {
      ++outside;
      continue;
    }
    // Behind a moving object: not visible, and its texture would fool the search.
    const Eigen::Vector2f xy_pred = pc.hnormalized().cast<float>();
    bool occluded = false;
    for (const auto& hull : frame.moving_hulls_xy) occluded = occluded || InsideConvexHull(hull, xy_pred);
    if (occluded) continue;
    ++searched;
    const PatchMatch m = FindPatchZssd(frame.image, p->patch, pred.cast<float>(), options_.guided_radius_px);
    if (!m.found || m.second < 1.5f * m.score) {
      ++ambiguous;
      continue;
    }
    cv::Mat found;
    if (!ExtractPatch(frame.image, m.uv, p->patch.cols, &found) || PatchNcc(found, p->patch) < options_.guided_min_ncc) {
      ++unlike;
      continue;
    }
    point_ids->push_back(pid);
    uv->push_back(m.uv);
    xy->push_back(K.PixelToNormalized(m.uv.cast<double>()));
  }
  MBSLAM_LOG(DEBUG) << log_name_ << " frame " << frame.frame_index << ": guided matching over "
                    << candidates.size() << " points of the last keyframes: " << tracked
                    << " held by tracks (" << ended << " of them ended), " << outside
                    << " outside, " << searched << " searched, " << ambiguous << " ambiguous, "
                    << unlike << " unlike, " << point_ids->size() << " re-found";
}

bool SlamSystem::Relocalize(const SlamFrame& frame, Map* map, int min_inliers,
                            const std::string& map_name, std::vector<Eigen::Vector3d>* X,
                            std::vector<Eigen::Vector2d>* xy, std::vector<int64_t>* tracks,
                            std::vector<cv::Mat>* patches, std::vector<int64_t>* refound_ids,
                            std::vector<Eigen::Vector2f>* refound_uv, PoseEstimate* est) {
  if (!frame.intrinsics || frame.image.empty()) return false;
  // The described points not already among the correspondences (through a track or
  // guided matching), and not behind a moving object.
  std::unordered_set<int64_t> taken(refound_ids->begin(), refound_ids->end());
  for (int64_t t : *tracks) {
    if (t >= 0) taken.insert(map->PointOfTrack(t));
  }
  std::vector<int64_t> ids;
  std::vector<OrbDescriptor> descriptors;
  for (const auto& [pid, p] : map->points()) {
    if (!p.has_descriptor || p.occluded || taken.count(pid)) continue;
    ids.push_back(pid);
    descriptors.push_back(p.descriptor);
  }
  if (static_cast<int>(ids.size() + X->size()) < min_inliers) return false;
  // The image's corners, once per image (it may be tried against several maps).
  if (orb_image_.data != frame.image.data || orb_frame_ != frame.frame_index) {
    orb_corners_.clear();
    orb_descriptors_.clear();
    DetectOrb(frame.image, options_.reloc_features, options_.reloc_fast_threshold, &orb_corners_,
              &orb_descriptors_);
    orb_image_ = frame.image;
    orb_frame_ = frame.frame_index;
  }
  const std::vector<Eigen::Vector2f>& corners = orb_corners_;
  std::vector<std::pair<int, int>> matches =
      MatchOrb(orb_descriptors_, descriptors, options_.reloc_max_hamming, options_.reloc_ratio);
  const size_t first = refound_ids->size();
  const size_t first_correspondence = X->size();
  // The matches (corner, index into ids) become correspondences after the map's own.
  const auto append_matches = [&]() {
    X->resize(first_correspondence);
    xy->resize(first_correspondence);
    tracks->resize(first_correspondence);
    patches->resize(first_correspondence);
    refound_ids->resize(first);
    refound_uv->resize(first);
    for (const auto& [c, m] : matches) {
      const Eigen::Vector2f& uv = corners[static_cast<size_t>(c)];
      const int64_t pid = ids[static_cast<size_t>(m)];
      X->push_back(map->point(pid)->position);
      xy->push_back(frame.intrinsics->PixelToNormalized(uv.cast<double>()));
      tracks->push_back(-1 - static_cast<int64_t>(refound_ids->size()));
      patches->emplace_back();
      refound_ids->push_back(pid);
      refound_uv->push_back(uv);
    }
  };
  const auto matched_inliers_of = [&](const PoseEstimate& e) {
    int n = 0;
    for (size_t i = first_correspondence; i < tracks->size() && i < e.inliers.size(); ++i)
      n += e.inliers[i];
    return n;
  };
  append_matches();
  PoseEstimatorOptions pose = options_.pose;
  pose.ransac_iterations = options_.reloc_ransac_iterations;
  *est = PoseEstimate();
  if (static_cast<int>(X->size()) >= std::min(min_inliers, options_.reloc_seed_inliers)) {
    *est = EstimatePose(*X, *xy, frame.focal_px, std::nullopt, pose);
  }
  int matched_inliers = matched_inliers_of(*est);
  const int seed_matches = static_cast<int>(matches.size());
  // Search by projection: a first pose from at least reloc_seed_inliers matched inliers
  // projects every described point, and each takes the most similar corner (ratio test)
  // within reloc_search_radius_px of it; the image is resected again on those matches.
  // Matching among the few corners near a projection finds the points whose descriptors
  // changed too much to win among all (a camera come back from further along, turned).
  if (options_.reloc_search_radius_px > 0.0 && est->ok &&
      matched_inliers >= options_.reloc_seed_inliers) {
    const CameraIntrinsics& K = *frame.intrinsics;
    std::vector<Eigen::Vector2f> projected(ids.size(), Eigen::Vector2f::Constant(NAN));
    for (size_t m = 0; m < ids.size(); ++m) {
      const Eigen::Vector3d pc = est->cam_from_world * map->point(ids[m])->position;
      if (pc.z() <= 0.0) continue;
      const Eigen::Vector2d uv = K.Project(pc);
      if (uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() < K.width && uv.y() < K.height)
        projected[m] = uv.cast<float>();
    }
    const std::vector<std::pair<int, int>> found = MatchOrbWithinRadius(
        projected, descriptors, corners, orb_descriptors_, options_.reloc_search_radius_px,
        options_.reloc_max_hamming, options_.reloc_ratio);
    if (static_cast<int>(found.size()) >= min_inliers) {
      const std::vector<std::pair<int, int>> seed = std::move(matches);
      matches.clear();
      for (const auto& [m, c] : found) matches.emplace_back(c, m);
      std::sort(matches.begin(), matches.end());  // by corner, as the first matches
      append_matches();
      PoseEstimate refined = EstimatePose(*X, *xy, frame.focal_px, est->cam_from_world, pose);
      if (refined.ok && matched_inliers_of(refined) >= matched_inliers) {
        *est = refined;
        matched_inliers = matched_inliers_of(refined);
      } else {  // back to the first matches
        matches = seed;
        append_matches();
      }
    }
  }
  const int need = std::max(min_inliers, options_.min_tracking_inliers);
  // The matches must place it, not the map's own correspondences alone (RANSAC re-run
  // on the tracks that just failed).
  const bool ok = est->ok && est->num_inliers >= need && matched_inliers >= min_inliers;
  std::ostringstream what;
  what << log_name_ << " frame " << frame.frame_index << ": relocalisation in " << map_name << " "
       << (ok ? "placed the image" : "failed") << ": " << corners.size() << " corners, "
       << descriptors.size() << " described points, " << seed_matches << " matches ("
       << matches.size() << " after the search by projection), inliers " << est->num_inliers << " ("
       << matched_inliers << " of the matches) of " << X->size() << " correspondences";
  if (ok) {
    MBSLAM_LOG(INFO) << what.str();
  } else {
    MBSLAM_LOG(DEBUG) << what.str();
  }
  if (!ok) return false;
  // Matched points without a guided matching template get one from this image.
  for (size_t i = 0; i < tracks->size() && i < est->inliers.size(); ++i) {
    if ((*tracks)[i] >= 0 || !est->inliers[i]) continue;
    const size_t k = static_cast<size_t>(-1 - (*tracks)[i]);
    MapPoint* p = map->point((*refound_ids)[k]);
    if (p && p->patch.empty())
      ExtractPatch(frame.image, (*refound_uv)[k], options_.reloc_patch_px, &p->patch);
  }
  return true;
}

std::vector<int64_t> SlamSystem::NearestKeyframes(const Rigid3d& cam_from_world, int count) const {
  // Keyframes looking the same way (optical axes within kMaxAxisAngle), nearest centre first.
  constexpr double kMaxAxisAngle = 60.0 * kDeg;
  const Eigen::Vector3d centre = cam_from_world.Inverse().translation;
  const Eigen::Vector3d axis = cam_from_world.rotation.inverse() * Eigen::Vector3d::UnitZ();
  std::vector<std::pair<double, int64_t>> ranked;
  for (const auto& [id, k] : map_.keyframes()) {
    const Rigid3d world_from_kf = k.cam_from_world.Inverse();
    const Eigen::Vector3d kf_axis = world_from_kf.rotation * Eigen::Vector3d::UnitZ();
    if (axis.dot(kf_axis) < std::cos(kMaxAxisAngle)) continue;
    ranked.emplace_back((world_from_kf.translation - centre).squaredNorm(), id);
  }
  const size_t n = std::min(ranked.size(), static_cast<size_t>(std::max(count, 0)));
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(n), ranked.end());
  std::vector<int64_t> ids;
  for (size_t i = 0; i < n; ++i) ids.push_back(ranked[i].second);
  return ids;
}

int SlamSystem::DescribeKeyframePoints(const cv::Mat& image, int64_t keyframe_id) {
  const Keyframe* k = map_.keyframe(keyframe_id);
  if (!k || image.empty()) return 0;
  std::vector<int64_t> ids;
  std::vector<Eigen::Vector2f> uv;
  for (const auto& [track, px] : k->track_uv) {
    const int64_t pid = map_.PointOfTrack(track);
    if (pid < 0) continue;
    ids.push_back(pid);
    uv.push_back(px.cast<float>());
  }
  std::vector<OrbDescriptor> descriptors;
  std::vector<uint8_t> valid;
  DescribeOrbAt(image, uv, &descriptors, &valid);
  int described = 0;
  for (size_t i = 0; i < ids.size(); ++i) {
    if (!valid[i]) continue;
    MapPoint* p = map_.point(ids[i]);
    p->descriptor = descriptors[i];
    p->has_descriptor = true;
    ++described;
  }
  return described;
}

std::optional<Rigid3d> SlamSystem::PredictPose(const SlamFrame& frame) const {
  if (recent_poses_.empty()) return std::nullopt;
  auto last = recent_poses_.rbegin();
  const int64_t a = last->first;
  const Rigid3d Ta = *PoseOf(a);
  // Odometry: the camera motion since frame a (metric map: directly; otherwise the
  // rotation only, translation from constant velocity below).
  std::optional<Rigid3d> odo_delta;
  auto oa = recent_odometry_.find(a);
  if (options_.use_odometry && frame.odom_from_cam && oa != recent_odometry_.end()) {
    odo_delta = frame.odom_from_cam->Inverse() * oa->second;  // cam_n_from_cam_a
  }
  if (odo_delta && metric_) return *odo_delta * Ta;
  if (recent_poses_.size() < 2) return odo_delta ? Rigid3d(odo_delta->rotation, Eigen::Vector3d::Zero()) * Ta : Ta;
  auto prev = std::next(last);
  const int64_t b = prev->first;
  const Vector6d xi = (Ta * PoseOf(b)->Inverse()).Log() / static_cast<double>(a - b);
  return Rigid3d::Exp(xi * static_cast<double>(frame.frame_index - a)) * Ta;
}

SlamPose SlamSystem::TrackPose(const SlamFrame& frame) {
  focal_px_ = frame.focal_px;
  depth_grids_.clear();
  MergeBundleAdjustment(/*wait=*/!options_.background_ba);
  if (frame.odom_from_cam) recent_odometry_[frame.frame_index] = *frame.odom_from_cam;
  while (recent_odometry_.size() > 64) recent_odometry_.erase(recent_odometry_.begin());
  SlamPose out;
  if (!options_.enabled) return out;
  frame_utime_[frame.frame_index] = frame.utime;
  if (!released_tracks_.empty()) {
    for (const SlamObservation& o : frame.observations) {
      auto it = released_tracks_.find(o.track_id);
      if (it != released_tracks_.end()) it->second = frame.frame_index;
    }
    for (auto it = released_tracks_.begin(); it != released_tracks_.end();) {
      const bool ended = frame.frame_index - it->second > kReleasedTrackMemoryFrames;
      it = ended ? released_tracks_.erase(it) : std::next(it);
    }
  }
  while (static_cast<int>(frame_utime_.size()) > options_.backfill_max_frames + 64) frame_utime_.erase(frame_utime_.begin());
  // A kept lost map that places this image is taken up again (lost: relocalised below).
  const bool rejoined = RejoinLostMap(frame);
  if (state_ == SlamState::kNotInitialized || state_ == SlamState::kInitializing) {
    const bool from_earlier_pair = TryInitialize(frame, &out);
    if (!from_earlier_pair) {
      last_frame_ = frame.frame_index;
      if (out.valid) {  // a map without confirmation: this image's pose is published
        RecordTrajectory(frame.frame_index, out.cam_from_world, map_.LastKeyframe());
        BackfillPoses(frame.frame_index, &out);
      } else {
        RememberUnposed(frame);
      }
      return out;
    }
    // The map was made from an earlier image's pair: this image is tracked on it (and
    // confirms it) like the images after an initialisation.
    out = SlamPose();
    if (state_ == SlamState::kTracking) BackfillPoses(frame.frame_index, &out);  // no confirmation
  }
  // Tracking: 2D-3D correspondences through the tracks that observe map points and
  // were not labelled moving.
  std::vector<Eigen::Vector3d> X;
  std::vector<Eigen::Vector2d> xy;
  std::vector<int64_t> tracks;
  std::vector<cv::Mat> patches;
  // Static tracks without a point (track id, normalised xy): a later keyframe may give
  // them one, which the trajectory files' re-resection of this image then uses.
  std::vector<std::pair<int64_t, Eigen::Vector2d>> unmapped_static;
  for (const SlamObservation& o : frame.observations) {
    if (o.body_id != 0) continue;  // only tracks segmentation holds static
    const int64_t pid = map_.PointOfTrack(o.track_id);
    if (pid < 0) {
      unmapped_static.emplace_back(o.track_id, o.xy);
      continue;
    }
    const MapPoint* p = map_.point(pid);
    X.push_back(p->position);
    xy.push_back(o.xy);
    tracks.push_back(o.track_id);
    patches.push_back(o.patch);
  }
  const std::optional<Rigid3d> prior = PredictPose(frame);
  // Stage 2 (guided matching): points that lost their tracks are searched around their
  // projection from the predicted pose, then everything is resected together.
  std::vector<int64_t> refound_ids;
  std::vector<Eigen::Vector2f> refound_uv;
  if (options_.guided_matching && prior && frame.intrinsics && !frame.image.empty()) {
    std::vector<Eigen::Vector2d> gxy;
    FindUntrackedPoints(frame, *prior, &refound_ids, &gxy, &refound_uv);
    for (size_t i = 0; i < refound_ids.size(); ++i) {
      X.push_back(map_.point(refound_ids[i])->position);
      xy.push_back(gxy[i]);
      tracks.push_back(-1 - static_cast<int64_t>(i));  // marks a re-found point
      patches.emplace_back();
    }
  }
  out.num_correspondences = static_cast<int>(X.size());
  PoseEstimate est;
  if (X.size() >= 6) est = EstimatePose(X, xy, frame.focal_px, prior, options_.pose, TrackingRotationPrior(frame));
  bool good = est.ok && est.num_inliers >= options_.min_tracking_inliers;
  MBSLAM_LOG(DEBUG) << log_name_ << " frame " << frame.frame_index << ": correspondences "
                    << X.size() << " (re-found " << refound_ids.size() << "), inliers "
                    << est.num_inliers << ", rms " << est.rms_px << " px, points "
                    << map_.num_points() << ", keyframes " << map_.num_keyframes();
  bool assisted = false;
  if (!good && options_.hybrid_tracking && (state_ == SlamState::kTracking || state_ == SlamState::kLost) && prior &&
      hybrid_frames_ < options_.hybrid_max_frames) {
    assisted = TrackWithEpipolar(frame, X, xy, *prior, &est);
    good = assisted;
  }
  hybrid_frames_ = assisted ? hybrid_frames_ + 1 : 0;
  bool relocalized = false;
  if (!good && options_.relocalization &&
      (state_ == SlamState::kTracking || state_ == SlamState::kLost)) {
    if (rejoined && rejoin_placement_ && rejoin_placement_->frame_index == frame.frame_index) {
      // Placed in the kept map just taken up (its tracks hold none of its points, and
      // without a pose there was no guided matching: the correspondences are all its).
      Placement& p = *rejoin_placement_;
      X = std::move(p.X);
      xy = std::move(p.xy);
      tracks = std::move(p.tracks);
      patches = std::move(p.patches);
      refound_ids = std::move(p.refound_ids);
      refound_uv = std::move(p.refound_uv);
      est = std::move(p.est);
      rejoin_placement_.reset();
      relocalized = true;
    } else {
      relocalized = Relocalize(frame, &map_, options_.reloc_min_inliers, "the map", &X, &xy,
                               &tracks, &patches, &refound_ids, &refound_uv, &est);
    }
    if (relocalized) relocalized_map_ = true;
    good = relocalized;
  }
  if (good && state_ == SlamState::kConfirming) {
    const double ratio = static_cast<double>(est.num_inliers) / static_cast<double>(X.size());
    if (ratio < options_.init_confirm_inlier_ratio) {
      MBSLAM_LOG(INFO) << log_name_ << ": new map not confirmed (inlier share " << ratio
                       << "); retrying";
      RestartMap(bridge_);
      out.state = state_;
      RememberUnposed(frame);
      return out;
    }
    if (++confirm_count_ >= options_.init_confirm_frames) {
      state_ = SlamState::kTracking;
      bridge_.reset();
      out.relocalized = just_initialized_;
      MBSLAM_LOG(INFO) << log_name_ << ": map confirmed (" << map_.num_points() << " points)";
      BackfillPoses(frame.frame_index, &out);
    }
  }
  if (good) {
    const bool recovered = state_ == SlamState::kLost;
    if (recovered) state_ = SlamState::kTracking;
    lost_frames_ = 0;
    if (relocalized) {
      out.relocalized = true;
      out.placed_by_relocalization = true;
      awaiting_loaded_map_ = false;
      ++relocalizations_;
    }
    out.valid = state_ == SlamState::kTracking;
    out.cam_from_world = est.cam_from_world;
    out.covariance = est.covariance;
    out.num_inliers = est.num_inliers;
    last_inliers_ = est.num_inliers;
    out.num_refound = 0;
    out.epipolar_assisted = assisted;
    StorePose(frame.frame_index, est.cam_from_world, est.covariance, assisted);
    // Published poses only: a confirming map's images are back-filled once it is
    // confirmed (or never, if it is dropped).
    // Back on the same map after a loss: the images lost meanwhile are resected on it now
    // (else they would wait, unposed, for the next map), before this one in time order.
    if (recovered && out.valid) BackfillPoses(frame.frame_index, &out);
    if (out.valid) RecordTrajectory(frame.frame_index, est.cam_from_world, map_.LastKeyframe());
    if (out.valid && options_.adjusted_trajectory_refine_keyframes > 0 && options_.adjusted_trajectory_max_poses > 0) {
      RefineObservations& obs = refine_obs_[frame.frame_index];
      obs.inliers.clear();
      for (size_t i = 0; i < tracks.size(); ++i) {
        if (i >= est.inliers.size() || !est.inliers[i]) continue;
        const int64_t pid = tracks[i] >= 0 ? map_.PointOfTrack(tracks[i]) : refound_ids[static_cast<size_t>(-1 - tracks[i])];
        if (pid >= 0) obs.inliers.emplace_back(pid, xy[i]);
      }
      obs.later.clear();
      if (options_.adjusted_trajectory_later_points_px > 0.0) obs.later = std::move(unmapped_static);
      while (refine_obs_.size() > 256) refine_obs_.erase(refine_obs_.begin());
    }
    if (options_.hybrid_tracking) {
      auto& seen = posed_xy_[frame.frame_index];
      seen.clear();
      for (const SlamObservation& o : frame.observations) seen.emplace(o.track_id, o.xy);
      while (static_cast<int>(posed_xy_.size()) > options_.hybrid_reference_frames) posed_xy_.erase(posed_xy_.begin());
    }
    for (size_t i = 0; i < tracks.size(); ++i) {
      if (tracks[i] < 0) {  // re-found by guided matching
        const size_t k = static_cast<size_t>(-1 - tracks[i]);
        if (est.inliers[i]) {
          out.refound.emplace_back(refound_ids[k], refound_uv[k]);
          if (MapPoint* p = map_.point(refound_ids[k])) p->last_seen_frame = frame.frame_index;
        }
        continue;
      }
      const int64_t pid = map_.PointOfTrack(tracks[i]);
      MapPoint* p = map_.point(pid);
      if (!p) continue;
      ++p->times_visible;
      if (est.inliers[i]) {
        ++p->times_found;
        p->last_seen_frame = frame.frame_index;
        p->occluded = false;
        if (!patches[i].empty()) p->patch = patches[i];
      } else {
        p->released_frame = frame.frame_index;
        map_.ReleaseTrack(tracks[i]);  // the track drifted off its point
        if (options_.released_tracks_stay_unmapped) released_tracks_[tracks[i]] = frame.frame_index;
      }
    }
  } else {
    ++lost_frames_;
    if (state_ == SlamState::kConfirming) {
      RestartMap(bridge_);
    } else {
      state_ = SlamState::kLost;
      // A loaded map waits longer for the camera to come back into it.
      const int give_up =
          awaiting_loaded_map_ ? options_.reloc_loaded_max_frames : options_.lost_frames_to_reinit;
      if (give_up > 0 && lost_frames_ >= give_up) {
        MBSLAM_LOG(WARNING) << log_name_ << ": lost for " << lost_frames_ << " frames"
                            << (awaiting_loaded_map_ ? " without relocalising in the loaded map"
                                                     : "")
                            << "; re-initialising";
        awaiting_loaded_map_ = false;
        // A bundle adjustment still running is waited for by the restart anyway: its
        // result is merged first, for the pose and the depths the bridge carries over.
        MergeBundleAdjustment(/*wait=*/true);
        std::optional<Bridge> bridge;
        if (recent_poses_.size() >= 2) {
          auto last = recent_poses_.rbegin();
          auto prev = std::next(last);
          Bridge b;
          b.frame = last->first;
          b.cam_from_world = *PoseOf(last->first);
          b.twist_per_frame = (b.cam_from_world * PoseOf(prev->first)->Inverse()).Log() /
                              static_cast<double>(last->first - prev->first);
          b.metric = metric_;
          if (const Keyframe* kf = map_.LastKeyframe()) {
            std::vector<double> depths;
            for (int64_t pid : kf->point_ids) {
              const MapPoint* p = map_.point(pid);
              if (!p) continue;
              const double z = (b.cam_from_world * p->position).z();
              if (z > 0.0) depths.push_back(z);
            }
            if (depths.size() >= 8) b.median_depth = Median(depths);
          }
          if (options_.bridge_ground) b.ground = ground_plane_;
          bridge = b;
        }
        KeepLostMap();
        RestartMap(bridge);
        just_initialized_ = true;
      }
    }
  }
  out.state = state_;
  out.metric = metric_;
  out.scale_to_metric = metric_ ? 1.0 : 0.0;
  out.relocalized_map = relocalized_map_;
  out.rejoined_kept_map = rejoined && out.valid;
  last_frame_ = frame.frame_index;
  if (!out.valid) RememberUnposed(frame);
  return out;
}

bool SlamSystem::TrackWithEpipolar(const SlamFrame& frame, const std::vector<Eigen::Vector3d>& X,
                                   const std::vector<Eigen::Vector2d>& xy, const Rigid3d& prior, PoseEstimate* est) {
  // Links: every track not held by a moving object (static ones, and those segmentation
  // has not placed yet: new, or unexplained but in no object; a minority on movers is
  // refused as outliers by the robust estimate), to the oldest recent posed image that
  // saw it (the longest baseline).
  EpipolarLinks links;
  // An edge's track slides along it: its link would pull the geometry (a track without
  // a patch is kept).
  std::unordered_set<int64_t> edge_like;
  if (options_.hybrid_min_corner_ratio > 0.0) {
    for (const SlamObservation& o : frame.observations) {
      if (o.body_id > 0 || o.patch.empty()) continue;  // never linked / no evidence
      if (PatchCornerRatio(o.patch) < options_.hybrid_min_corner_ratio) edge_like.insert(o.track_id);
    }
  }
  std::vector<int64_t> ref_frames;
  std::vector<int> per_reference;
  std::unordered_set<int64_t> linked;
  for (const auto& [f, seen] : posed_xy_) {
    if (f >= frame.frame_index) continue;
    const std::optional<Rigid3d> T = PoseOf(f);
    if (!T) continue;
    const int r = static_cast<int>(ref_frames.size());
    int count = 0;
    for (const SlamObservation& o : frame.observations) {
      if (o.body_id > 0 || linked.count(o.track_id)) continue;
      if (edge_like.count(o.track_id)) continue;
      auto it = seen.find(o.track_id);
      if (it == seen.end()) continue;
      linked.insert(o.track_id);
      links.reference.push_back(r);
      links.xy_ref.push_back(it->second);
      links.xy_cur.push_back(o.xy);
      ++count;
    }
    ref_frames.push_back(f);
    per_reference.push_back(count);
    links.references.push_back(*T);
  }
  if (static_cast<int>(links.xy_ref.size()) < options_.hybrid_min_links) {
    MBSLAM_LOG(DEBUG) << log_name_ << " frame " << frame.frame_index
                      << ": epipolar-assisted pose refused, " << links.xy_ref.size()
                      << " tracks linked (" << edge_like.size() << " edge-like tracks left out)";
    return false;
  }
  const int start_reference = static_cast<int>(
      std::max_element(per_reference.begin(), per_reference.end()) - per_reference.begin());
  const int length_reference = static_cast<int>(ref_frames.size()) - 1;
  // The expected length: the speed of the camera over the recent map-based poses (held
  // through a run of these poses, which would otherwise feed their own drift back).
  if (hybrid_frames_ == 0) {
    hybrid_speed_ = -1.0;
    double path = 0.0;
    int64_t first = -1, last = -1;
    std::optional<Eigen::Vector3d> previous;
    for (auto it = recent_poses_.rbegin(); it != recent_poses_.rend() && (first < 0 || last - first < 10); ++it) {
      const std::optional<Rigid3d> T = PoseOf(it->first);
      if (!T) continue;
      const Eigen::Vector3d centre = T->Inverse().translation;
      if (previous) path += (centre - *previous).norm();
      previous = centre;
      if (last < 0) last = it->first;
      first = it->first;
    }
    if (last > first) hybrid_speed_ = path / static_cast<double>(last - first);
  }
  const Rigid3d& length_ref = links.references.back();
  const double expected_length = hybrid_speed_ >= 0.0
                                     ? hybrid_speed_ * static_cast<double>(frame.frame_index - ref_frames.back())
                                     : (prior * length_ref.Inverse()).translation.norm();
  HybridPoseEstimate h = EstimatePoseWithEpipolar(
      X, xy, links, prior, start_reference, length_reference, expected_length,
      options_.hybrid_length_sigma, frame.focal_px, options_.pose);
  // The ground's length, along the direction just estimated, when enough links agree on it.
  if (options_.hybrid_ground_length && ground_plane_ && h.pose.ok) {
    const GroundLengthEstimate g = GroundLengthOfMotion(
        links, h.link_inliers, *ground_plane_, length_ref, h.pose.cam_from_world, frame.focal_px,
        options_.hybrid_ground_min_elevation_deg * kDeg, options_.hybrid_ground_max_error_px,
        options_.hybrid_ground_length_step);
    const bool use = GroundLengthIsUsable(g, options_);
    MBSLAM_LOG(DEBUG) << log_name_ << " frame " << frame.frame_index << ": ground length "
                      << g.length << " (held speed's " << expected_length << "), " << g.support
                      << " of " << g.candidates << " ground links agree (" << g.support_shorter
                      << " / " << g.support_longer << " at -+" << options_.hybrid_ground_length_step
                      << ")" << (use ? "" : ": not used");
    if (use) {
      HybridPoseEstimate hg = EstimatePoseWithEpipolar(
          X, xy, links, prior, start_reference, length_reference, g.length,
          options_.hybrid_ground_length_sigma, frame.focal_px, options_.pose);
      if (hg.pose.ok) {
        h = std::move(hg);
        // The run's later images hold this speed instead.
        if (frame.frame_index > ref_frames.back()) {
          hybrid_speed_ = g.length / static_cast<double>(frame.frame_index - ref_frames.back());
        }
      }
    }
  }
  const bool ok = h.pose.ok && h.num_link_inliers >= options_.hybrid_min_links &&
                  h.num_link_inliers >= options_.hybrid_min_link_ratio * static_cast<double>(links.xy_ref.size());
  MBSLAM_LOG(DEBUG) << log_name_ << " frame " << frame.frame_index << ": epipolar-assisted pose, "
                    << h.num_link_inliers << " of " << links.xy_ref.size()
                    << " tracks linked to images " << ref_frames.front() << "-" << ref_frames.back()
                    << " (rms " << h.link_rms_px << " px), " << h.pose.num_inliers << " of "
                    << X.size() << " map points, " << edge_like.size()
                    << " edge-like tracks left out" << (ok ? "" : ": refused");
  if (!ok) return false;
  *est = h.pose;
  return true;
}

void SlamSystem::RememberUnposed(const SlamFrame& frame) {
  if (options_.backfill_max_frames <= 0) return;
  auto& obs = unposed_[frame.frame_index];
  obs.clear();
  // Every track: only those that become static map points are used, whatever their
  // label was then (the first images have no labels yet).
  for (const SlamObservation& o : frame.observations) obs.emplace_back(o.track_id, o.xy);
  while (static_cast<int>(unposed_.size()) > options_.backfill_max_frames) unposed_.erase(unposed_.begin());
}

void SlamSystem::BackfillPoses(int64_t frame, SlamPose* out) {
  for (const auto& [f, obs] : unposed_) {
    if (f >= frame) break;
    // Images of the initialisation and confirmation already have poses in the new map.
    if (const std::optional<Rigid3d> known = PoseOf(f)) {
      out->backfilled.emplace_back(f, *known);
      continue;
    }
    // Others are resected against the new map through their tracks' points.
    std::vector<Eigen::Vector3d> X;
    std::vector<Eigen::Vector2d> xy;
    for (const auto& [track, x] : obs) {
      const int64_t pid = map_.PointOfTrack(track);
      if (pid < 0) continue;
      X.push_back(map_.point(pid)->position);
      xy.push_back(x);
    }
    if (X.size() < 6) {
      MBSLAM_LOG(DEBUG) << log_name_ << " backfill of frame " << f << ": " << obs.size()
                        << " observations, " << X.size() << " with points: too few";
      continue;
    }
    const PoseEstimate est = EstimatePose(X, xy, focal_px_, std::nullopt, options_.pose);
    MBSLAM_LOG(DEBUG) << log_name_ << " backfill of frame " << f << ": " << obs.size()
                      << " observations, " << X.size() << " with points, " << est.num_inliers
                      << " inliers" << (est.ok ? "" : " (failed)");
    if (est.ok && est.num_inliers >= options_.min_tracking_inliers) out->backfilled.emplace_back(f, est.cam_from_world);
  }
  for (const auto& [f, T] : out->backfilled) {
    // Anchored on the keyframe nearest in time.
    const Keyframe* nearest = nullptr;
    for (const auto& [id, k] : map_.keyframes()) {
      if (!nearest || std::abs(k.frame_index - f) < std::abs(nearest->frame_index - f)) nearest = &k;
    }
    RecordTrajectory(f, T, nearest);
  }
  // The images that got no pose are not kept for a later map: said, not hidden.
  const size_t earlier = static_cast<size_t>(std::count_if(
      unposed_.begin(), unposed_.end(), [frame](const auto& u) { return u.first < frame; }));
  if (earlier > 0) {
    MBSLAM_LOG(INFO) << log_name_ << ": poses of " << out->backfilled.size() << " of " << earlier
                     << " earlier images recovered against the map";
  }
  unposed_.clear();
}

bool SlamSystem::TryInitialize(const SlamFrame& frame, SlamPose* out) {
  const InitAttempt attempt = AttemptInitialize(frame, out);
  // An image too close to the reference to judge (kDeferred), or one whose parallax was
  // given back (a sideways sway, init_wait_through_low_parallax), leaves the waiting pair
  // standing until its wait ends; then it makes the map and this image is tracked on it.
  if (attempt == InitAttempt::kDeferred || attempt == InitAttempt::kWaitEnded ||
      (attempt == InitAttempt::kRefusedParallax && init_pending_pair_ && options_.init_wait_through_low_parallax)) {
    if (!init_pending_pair_ || (attempt != InitAttempt::kWaitEnded &&
                                frame.frame_index - init_pending_frame_ < options_.init_wait_frames)) {
      return false;
    }
    BuildWaitingPair(frame.frame_index, "the wait for parallax ended", out);
    return true;
  }
  if (attempt == InitAttempt::kBuilt || attempt == InitAttempt::kRefusedGeometry ||
      attempt == InitAttempt::kRefusedParallax || !options_.init_wait_fallback) {
    // A pair of the same reference refused for its geometry (E or pose recovery failed,
    // too few points), or, with init_wait_through_low_parallax off, for too little
    // parallax, contradicts the waiting pair (the parallax that had came from something
    // else): the wait starts again.
    if (init_pending_pair_ && (attempt == InitAttempt::kRefusedGeometry || attempt == InitAttempt::kRefusedParallax)) {
      init_pending_frame_ = -1;
    }
    init_pending_pair_.reset();
    return false;
  }
  if (!init_pending_pair_) return false;
  // The wait for more parallax ended without a better pair (the shared tracks thinned
  // out or no longer span the image): the waiting pair makes the map, and this image is
  // tracked on it.
  BuildWaitingPair(frame.frame_index, "no acceptable pair", out);
  return true;
}

void SlamSystem::BuildWaitingPair(int64_t frame_index, const char* why, SlamPose* out) {
  const InitPair pair = std::move(*init_pending_pair_);
  init_pending_pair_.reset();
  MBSLAM_LOG(DEBUG) << log_name_ << " init at frame " << frame_index << ": " << why
                    << ", the pair of frames " << pair.ref_frame << "-" << pair.frame_index
                    << " (waiting for parallax) makes the map";
  BuildInitialMap(pair, out);
}

SlamSystem::InitAttempt SlamSystem::AttemptInitialize(const SlamFrame& frame, SlamPose* out) {
  out->state = state_;
  std::unordered_map<int64_t, Eigen::Vector2d> current;
  for (const SlamObservation& o : frame.observations) {
    // Static, or not yet judged (new) and not believed moving; movers stay out.
    if (o.body_id == 0 || (o.body_id < 0 && o.p_static >= 0.5)) current[o.track_id] = o.xy;
  }
  auto set_reference = [&]() {
    if (static_cast<int>(current.size()) < options_.init_min_tracks) {
      init_ref_frame_ = -1;
      init_pending_frame_ = -1;
      state_ = SlamState::kNotInitialized;
      return;
    }
    init_ref_frame_ = frame.frame_index;
    init_pending_frame_ = -1;
    init_ref_xy_ = current;
    init_ref_odom_ = frame.odom_from_cam;
    init_ref_rotation_prior_ = frame.rotation_prior;
    init_ref_utime_ = frame.utime;
    state_ = SlamState::kInitializing;
  };
  if (init_ref_frame_ < 0 || frame.frame_index - init_ref_frame_ > options_.init_max_frames) {
    set_reference();
    out->state = state_;
    return InitAttempt::kRefusedTracks;
  }
  std::vector<int64_t> ids;
  std::vector<Eigen::Vector2d> xr, xn;
  std::vector<double> disp;
  for (const auto& [id, x] : current) {
    auto it = init_ref_xy_.find(id);
    if (it == init_ref_xy_.end()) continue;
    ids.push_back(id);
    xr.push_back(it->second);
    xn.push_back(x);
    disp.push_back((x - it->second).norm() * frame.focal_px);
  }
  // While an acceptable pair waits for parallax, its reference is kept as long as
  // init_min_points tracks are shared (init_min_tracks are needed to start one): this
  // image may still make a pair with more parallax, else the waiting pair makes the map.
  const int min_shared = init_pending_pair_ && options_.init_wait_fallback
                             ? options_.init_min_points
                             : options_.init_min_tracks;
  if (static_cast<int>(ids.size()) < min_shared) {
    set_reference();  // the reference has too few tracks left
    out->state = state_;
    return InitAttempt::kRefusedTracks;
  }
  // Not enough motion yet (a pending pair keeps waiting).
  if (Median(disp) < 8.0) return InitAttempt::kDeferred;

  const double thresh = 1.0 / frame.focal_px;
  std::unordered_set<int64_t> other_motion;  // members of the motions not chosen (kept out of the map)
  // The static world is the motion that spans the image, not the one with most inliers
  // (a large moving object the camera follows would win a plain RANSAC), and not one
  // inside moving-object hulls.
  if (options_.init_max_motions > 1 || options_.init_min_coverage > 0.0 || options_.init_max_hull_share < 1.0) {
    std::vector<Eigen::Vector2d> all_xy;
    all_xy.reserve(frame.observations.size());
    for (const SlamObservation& o : frame.observations) all_xy.push_back(o.xy);
    std::vector<InitMotionGroup> groups =
        FindMotionGroups(xr, xn, thresh, options_.init_min_points, options_.init_max_motions);
    ScoreMotionGroups(xn, all_xy, frame.moving_hulls_xy, kInitGridCols, kInitGridRows, &groups);
    const int g = SelectStaticGroup(groups, options_.init_min_coverage, options_.init_max_hull_share);
    if (GetLogLevel() <= LogLevel::kDebug) {
      for (size_t k = 0; k < groups.size(); ++k) {
        MBSLAM_LOG(DEBUG) << log_name_ << " init frame " << frame.frame_index << ": motion " << k
                          << " of " << ids.size() << " tracks: " << groups[k].count
                          << " inliers, coverage " << groups[k].coverage << ", in hulls "
                          << groups[k].hull_share;
      }
    }
    if (g < 0) {
      // The tracks shared with the reference no longer span the image (the background
      // left the view, or only an object was tracked): start again from this image.
      std::vector<InitMotionGroup> all(1);
      all[0].inliers.assign(ids.size(), 1);
      all[0].count = static_cast<int>(ids.size());
      ScoreMotionGroups(xn, all_xy, {}, kInitGridCols, kInitGridRows, &all);
      MBSLAM_LOG(DEBUG) << log_name_ << " init refused at frame " << frame.frame_index
                        << ": no broad static motion among " << groups.size()
                        << " (largest: " << (groups.empty() ? 0 : groups[0].count)
                        << " inliers, coverage " << (groups.empty() ? 0.0 : groups[0].coverage)
                        << ", in hulls " << (groups.empty() ? 0.0 : groups[0].hull_share)
                        << "); shared tracks cover " << all[0].coverage;
      if (all[0].coverage < options_.init_min_coverage) set_reference();
      out->state = state_;
      return InitAttempt::kRefusedTracks;
    }
    // When the largest motion is the static world (the usual case) the two-view estimate
    // below runs on all tracks as before. Otherwise only the chosen motion's tracks enter
    // the map, and the other motions' tracks are kept out of both views.
    if (g > 0) {
      const InitMotionGroup& chosen = groups[static_cast<size_t>(g)];
      MBSLAM_LOG(INFO) << log_name_ << " init at frame " << frame.frame_index << ": motion " << g
                       << " (" << chosen.count << " inliers, coverage " << chosen.coverage
                       << ") is the static world, not the largest (" << groups[0].count
                       << " inliers, coverage " << groups[0].coverage << ")";
      std::vector<int64_t> ids_g;
      std::vector<Eigen::Vector2d> xr_g, xn_g;
      for (size_t i = 0; i < ids.size(); ++i) {
        if (chosen.inliers[i]) {
          ids_g.push_back(ids[i]);
          xr_g.push_back(xr[i]);
          xn_g.push_back(xn[i]);
        } else {
          for (const InitMotionGroup& other : groups) {
            if (other.inliers[i]) other_motion.insert(ids[i]);
          }
        }
      }
      ids = std::move(ids_g);
      xr = std::move(xr_g);
      xn = std::move(xn_g);
    }
  }

  const size_t n = ids.size();
  // Candidate motions: from E (recoverPose), or from the homography decomposition
  // when the homography explains the views (planar scene or too little parallax), or,
  // when both views carry a rotation prior of one reference, the known rotation with
  // the translation fitted to it (a small object spans a few degrees, where E confuses
  // a sideways translation with a turn).
  struct Candidate {
    Rigid3d cam1_from_cam0;
    cv::Mat mask;
  };
  std::vector<Candidate> candidates;
  const EssentialFit fit = FitEssential(xr, xn, thresh);
  if (!fit.ok()) {
    MBSLAM_LOG(DEBUG) << log_name_ << " init refused at frame " << frame.frame_index
                      << ": no essential matrix";
    return InitAttempt::kRefusedGeometry;
  }
  const std::vector<cv::Point2d>& pr = fit.pr;
  const std::vector<cv::Point2d>& pn = fit.pn;
  const cv::Mat& E = fit.E;
  const cv::Mat& e_mask = fit.mask;
  const int e_inl = fit.inliers;
  cv::Mat h_mask;
  int h_inl = 0;
  bool planar = false;
  // The body kept its rotation in the prior's frame when the known rotation explains
  // (nearly) as many correspondences as a free essential matrix; a turning body does not,
  // and its map then runs without the prior.
  rotation_prior_active_ = false;
  if (UsesRotationPrior() && frame.rotation_prior && init_ref_rotation_prior_ &&
      frame.rotation_prior->ref_id == init_ref_rotation_prior_->ref_id) {
    const Eigen::Matrix3d R =
        (frame.rotation_prior->cam_from_ref * init_ref_rotation_prior_->cam_from_ref.conjugate()).toRotationMatrix();
    const std::optional<KnownRotationTranslation> kt = TranslationGivenRotation(xr, xn, R, thresh, 200);
    if (kt && kt->count >= options_.init_min_points && kt->count >= options_.rotation_prior_min_inlier_ratio * e_inl) {
      rotation_prior_active_ = true;
      cv::Mat mask(static_cast<int>(n), 1, CV_8U);
      for (size_t i = 0; i < n; ++i) mask.at<uint8_t>(static_cast<int>(i)) = kt->inliers[i];
      for (double sign : {1.0, -1.0}) candidates.push_back(Candidate{Rigid3d(R, sign * kt->t_unit), mask});
    }
    MBSLAM_LOG(DEBUG) << log_name_ << " init frame " << frame.frame_index
                      << ": known rotation explains " << (kt ? kt->count : 0)
                      << " of the essential matrix's " << e_inl << " inliers"
                      << (rotation_prior_active_ ? "" : ": the body turns, no rotation prior");
  }
  if (!rotation_prior_active_) {
    cv::Mat H = cv::findHomography(pr, pn, cv::RANSAC, 1.5 * thresh, h_mask, 2000, 0.999);
    h_inl = H.empty() ? 0 : cv::countNonZero(h_mask);
    planar = h_inl >= options_.init_homography_ratio * e_inl;
    if (!planar) {
      cv::Mat R, t, mask = e_mask.clone();
      // recoverPose counts only the points nearer than 50 baselines (parallax above about
      // 1 deg): too few of them is a short baseline for the scene's depth (or an essential
      // matrix that does not fit, which a consistent one a few images later replaces). It
      // counts as too little parallax whatever the number of points, unlike the median
      // test below: the points it would count are the ones the short baseline leaves out
      // (measured as it is on the simulated scenes, TartanAir and DAVIS).
      const int in_front = cv::recoverPose(E.rowRange(0, 3), pr, pn, R, t, 1.0, cv::Point2d(0, 0), mask);
      if (in_front < options_.init_min_points) {
        MBSLAM_LOG(DEBUG) << log_name_ << " init refused at frame " << frame.frame_index
                          << ": E inliers " << e_inl << ", H inliers " << h_inl << ", " << in_front
                          << " in front of both views within 50 baselines";
        return InitAttempt::kRefusedParallax;
      }
      Eigen::Matrix3d Re;
      Eigen::Vector3d te;
      cv::cv2eigen(R, Re);
      cv::cv2eigen(t, te);
      candidates.push_back(Candidate{Rigid3d(Re, te.normalized()), mask});
    } else {
      std::vector<cv::Mat> Rs, ts, normals;
      cv::decomposeHomographyMat(H, cv::Mat::eye(3, 3, CV_64F), Rs, ts, normals);
      for (size_t i = 0; i < Rs.size(); ++i) {
        Eigen::Matrix3d Re;
        Eigen::Vector3d te;
        cv::cv2eigen(Rs[i], Re);
        cv::cv2eigen(ts[i], te);
        if (te.norm() < 1e-9) continue;
        candidates.push_back(Candidate{Rigid3d(Re, te.normalized()), h_mask});
      }
    }
  }
  // Triangulate each candidate; keep the one with most good points.
  struct Result {
    Rigid3d T;
    std::vector<std::pair<size_t, Eigen::Vector3d>> points;
    double median_parallax = 0.0;
  };
  std::optional<Result> best;
  const double max_err = options_.triangulation_max_error_px / frame.focal_px;
  for (const Candidate& c : candidates) {
    Result r;
    r.T = c.cam1_from_cam0;
    std::vector<double> parallax;
    for (size_t i = 0; i < n; ++i) {
      if (!c.mask.at<uint8_t>(static_cast<int>(i))) continue;
      const std::optional<Eigen::Vector3d> X = TriangulateDlt(Rigid3d(), xr[i], r.T, xn[i]);
      if (!X) continue;
      if (ReprojectionError(Rigid3d(), *X, xr[i]) > max_err || ReprojectionError(r.T, *X, xn[i]) > max_err) {
        continue;
      }
      const double angle = ParallaxAngle(Rigid3d(), r.T, *X);
      parallax.push_back(angle);
      if (angle < options_.triangulation_min_angle_deg * kDeg) continue;
      r.points.emplace_back(i, *X);
    }
    r.median_parallax = Median(parallax);
    if (!best || r.points.size() > best->points.size()) best = r;
  }
  if (!best || static_cast<int>(best->points.size()) < options_.init_min_points ||
      best->median_parallax < options_.init_min_parallax_deg * kDeg) {
    MBSLAM_LOG(DEBUG) << log_name_ << " init refused at frame " << frame.frame_index
                      << ": E inliers " << e_inl << ", H inliers " << h_inl
                      << (planar ? " (planar)" : "") << ", points "
                      << (best ? best->points.size() : 0) << ", median parallax "
                      << (best ? best->median_parallax / kDeg : 0.0) << " deg";
    // Refused for now; more parallax will come (or the reference is replaced). Too few
    // points counts against the waiting pair even where it is the tracks' lack (fewer
    // shared than a new start needs): made into the map then, TartanAir start 0's pair
    // of images 3-5 (58 points on a third of the image) drifted, ATE 0.67 -> 1.72 %.
    // Too little parallax (the baseline shrank, or has not grown yet) is told from the
    // other refusals: it does not contradict a pair that waits for more.
    const bool parallax_short = best && best->median_parallax < options_.init_min_parallax_deg * kDeg &&
                                static_cast<int>(best->points.size()) >= options_.init_min_points;
    return parallax_short ? InitAttempt::kRefusedParallax : InitAttempt::kRefusedGeometry;
  }
  // The points that would make the map (those with parallax) must span the image too:
  // when the background only rotates, a followed object is all that has parallax.
  double map_coverage = 1.0;
  if (options_.init_min_coverage > 0.0 || options_.init_max_hull_share < 1.0) {
    std::vector<Eigen::Vector2d> all_xy;
    all_xy.reserve(frame.observations.size());
    for (const SlamObservation& o : frame.observations) all_xy.push_back(o.xy);
    std::vector<InitMotionGroup> mapped(1);
    mapped[0].inliers.assign(n, 0);
    for (const auto& [i, X] : best->points) mapped[0].inliers[i] = 1;
    mapped[0].count = static_cast<int>(best->points.size());
    ScoreMotionGroups(xn, all_xy, frame.moving_hulls_xy, kInitGridCols, kInitGridRows, &mapped,
                      /*require_majority=*/false);
    map_coverage = mapped[0].coverage;
    if (SelectStaticGroup(mapped, options_.init_min_coverage, options_.init_max_hull_share) < 0) {
      MBSLAM_LOG(DEBUG) << log_name_ << " init refused at frame " << frame.frame_index << ": the "
                        << best->points.size() << " points with parallax cover " << map_coverage
                        << " of the image, " << mapped[0].hull_share << " inside moving hulls";
      return InitAttempt::kRefusedTracks;
    }
  }

  InitPair pair;
  pair.ref_frame = init_ref_frame_;
  pair.ref_utime = init_ref_utime_;
  pair.ref_xy = init_ref_xy_;
  pair.ref_odom = init_ref_odom_;
  pair.ref_rotation_prior = init_ref_rotation_prior_;
  pair.frame_index = frame.frame_index;
  pair.utime = frame.utime;
  pair.xy = current;
  for (const SlamObservation& o : frame.observations) {
    if (current.count(o.track_id)) pair.uv[o.track_id] = o.uv;
  }
  pair.image = frame.image;
  pair.odom = frame.odom_from_cam;
  pair.rotation_prior = frame.rotation_prior;
  pair.mean_gray = frame.mean_gray;
  pair.focal_px = frame.focal_px;
  pair.cam1_from_cam0 = best->T;
  pair.points.reserve(best->points.size());
  for (const auto& [i, X] : best->points) pair.points.push_back(InitPair::Point{ids[i], X, xr[i], xn[i]});
  pair.other_motion = std::move(other_motion);
  pair.planar = planar;
  pair.rotation_prior_active = rotation_prior_active_;
  pair.median_parallax_rad = best->median_parallax;
  pair.coverage = map_coverage;

  // Acceptable, but from a short baseline: wait for more parallax while the tracks last.
  if (options_.init_good_parallax_deg > 0.0 && best->median_parallax < options_.init_good_parallax_deg * kDeg) {
    const int shared = static_cast<int>(n);
    if (init_pending_frame_ < 0) {
      init_pending_frame_ = frame.frame_index;
      init_pending_tracks_ = shared;
      init_pending_parallax_ = best->median_parallax;
    }
    const int64_t waited = frame.frame_index - init_pending_frame_;
    bool reachable = true;
    if (options_.init_wait_projection_frames > 0 && waited >= options_.init_wait_projection_frames) {
      const double rate = std::max(0.0, best->median_parallax - init_pending_parallax_) / static_cast<double>(waited);
      reachable = best->median_parallax + rate * static_cast<double>(options_.init_wait_frames - waited) >=
                  options_.init_good_parallax_deg * kDeg;
    }
    if (waited < options_.init_wait_frames && reachable &&
        shared >= options_.init_wait_keep_ratio * init_pending_tracks_) {
      MBSLAM_LOG(DEBUG) << log_name_ << " init at frame " << frame.frame_index
                        << " deferred: median parallax " << best->median_parallax / kDeg << " deg, "
                        << shared << " of " << init_pending_tracks_
                        << " tracks shared (acceptable since frame " << init_pending_frame_ << ")";
      if (!options_.init_keep_best_pair || !init_pending_pair_ ||
          pair.median_parallax_rad >= init_pending_pair_->median_parallax_rad) {
        init_pending_pair_ = std::move(pair);
      }
      return InitAttempt::kDeferred;
    }
    // The wait ends: an earlier pair with more parallax than this one makes the map.
    if (options_.init_keep_best_pair && init_pending_pair_ &&
        init_pending_pair_->median_parallax_rad > pair.median_parallax_rad) {
      return InitAttempt::kWaitEnded;
    }
  }

  BuildInitialMap(pair, out);
  return InitAttempt::kBuilt;
}

void SlamSystem::BuildInitialMap(const InitPair& pair, SlamPose* out) {
  rotation_prior_active_ = pair.rotation_prior_active;
  // Build the map: keyframe 0 at the reference (fixed gauge), keyframe 1 at the pair's image.
  map_.Clear();
  recent_poses_.clear();
  // Scale: metric from the odometry baseline when available, else median depth 1.
  double scale = 1.0;
  metric_ = false;
  if (options_.use_odometry && pair.ref_odom && pair.odom) {
    const double baseline = (pair.odom->Inverse() * *pair.ref_odom).translation.norm();
    if (baseline > 1e-3) {
      scale = baseline;  // translation of the two-view motion has unit norm
      metric_ = true;
    }
  }
  if (!metric_) {
    std::vector<double> depths;
    for (const InitPair::Point& pt : pair.points) depths.push_back(pt.X.z());
    scale = 1.0 / std::max(1e-9, Median(depths));
  }
  Keyframe k0;
  k0.frame_index = pair.ref_frame;
  k0.utime = pair.ref_utime;
  k0.cam_from_world = Rigid3d();
  k0.rotation_prior = pair.ref_rotation_prior;
  k0.fixed = true;
  k0.track_xy = pair.ref_xy;
  Keyframe k1;
  k1.frame_index = pair.frame_index;
  k1.utime = pair.utime;
  k1.cam_from_world = Rigid3d(pair.cam1_from_cam0.rotation, pair.cam1_from_cam0.translation * scale);
  k1.track_xy = pair.xy;
  k1.track_uv = pair.uv;
  for (int64_t id : pair.other_motion) {
    k0.track_xy.erase(id);
    k1.track_xy.erase(id);
    k1.track_uv.erase(id);
  }
  if (pair.ref_odom) {
    k0.has_odometry = true;
    k0.odom_from_cam = *pair.ref_odom;
  }
  if (pair.odom) {
    k1.has_odometry = true;
    k1.odom_from_cam = *pair.odom;
  }
  k1.rotation_prior = pair.rotation_prior;
  const int64_t id0 = map_.AddKeyframe(std::move(k0));
  const int64_t id1 = map_.AddKeyframe(std::move(k1));
  for (const InitPair::Point& pt : pair.points) {
    MapPoint p;
    p.position = pt.X * scale;
    p.track_id = pt.track_id;
    p.created_frame = pair.frame_index;
    p.last_seen_frame = pair.frame_index;
    p.gray = pair.mean_gray;
    const int64_t pid = map_.AddPoint(std::move(p));
    map_.AddObservation(pid, id0, pt.xr);
    map_.AddObservation(pid, id1, pt.xn);
  }
  // Described at once: a map lost before its next keyframe can be relocalised in.
  if (options_.relocalization) DescribeKeyframePoints(pair.image, id1);
  // Global BA of the two views, inline.
  BaProblem problem = ExtractBa(2, true, pair.focal_px, metric_);
  const BaSummary s = SolveBa(&problem, options_.ba);
  if (s.usable) ApplyBaResult(problem, options_.ba, &map_);
  ++ba_runs_;
  if (bridge_) ApplyBridge(pair.ref_frame, pair.frame_index);
  const Keyframe& kf1 = *map_.keyframe(id1);
  // Covariances of the two views: small (a few hundredths of a pixel-equivalent).
  const Matrix6d init_cov = Matrix6d::Identity() * std::pow(0.5 / pair.focal_px, 2);
  FramePose p0;
  p0.cam_from_world = map_.keyframe(id0)->cam_from_world;
  p0.covariance = init_cov;
  p0.anchor_keyframe = id0;
  recent_poses_[pair.ref_frame] = p0;
  FramePose p1;
  p1.cam_from_world = kf1.cam_from_world;
  p1.covariance = init_cov;
  p1.anchor_keyframe = id1;
  recent_poses_[pair.frame_index] = p1;
  last_keyframe_frame_ = pair.frame_index;
  tracked_points_at_keyframe_ = static_cast<int>(map_.num_points());
  state_ = options_.init_confirm_frames > 0 ? SlamState::kConfirming : SlamState::kTracking;
  confirm_count_ = 0;
  MBSLAM_LOG(INFO) << log_name_ << ": initialised from frames " << pair.ref_frame << "-"
                   << pair.frame_index << " with " << map_.num_points() << " points ("
                   << (pair.planar ? "homography" : "essential") << ", median parallax "
                   << pair.median_parallax_rad / kDeg << " deg, coverage " << pair.coverage
                   << (metric_ ? ", metric scale from odometry" : "") << ")";
  out->state = state_;
  out->valid = state_ == SlamState::kTracking;
  out->cam_from_world = kf1.cam_from_world;
  out->covariance = Matrix6d::Identity() * 1e-4;
  out->num_inliers = static_cast<int>(map_.num_points());
  out->metric = metric_;
  out->scale_to_metric = metric_ ? 1.0 : 0.0;
}

void SlamSystem::ApplyBridge(int64_t ref_frame, int64_t cur_frame) {
  // Kept until the new map is confirmed (an unconfirmed map is dropped and the next
  // attempt needs the bridge again).
  const Bridge b = *bridge_;
  // The reference view's pose in the old world frame, carried over the gap.
  const Rigid3d ref_in_old = Rigid3d::Exp(b.twist_per_frame * static_cast<double>(ref_frame - b.frame)) * b.cam_from_world;
  // Units: metric maps are already comparable; otherwise (bridge_units) the new baseline
  // takes the length the old velocity predicts for it, or the new points the median
  // depth the old ones had in the last good view. A camera that speeds up or stops
  // during the gap fools the first (TartanAir: a segment at 0.6x the scale after the
  // camera accelerated 1.6x); an indoor scene's depth changes less.
  double scale = 1.0;
  bool ground_bridged = false;  // the units keep the camera's height above the old plane
  const Keyframe* k1 = map_.LastKeyframe();
  if (!(b.metric && metric_) && k1 != nullptr) {
    const double predicted = Rigid3d::Exp(b.twist_per_frame).translation.norm() * static_cast<double>(cur_frame - ref_frame);
    const double measured = k1->cam_from_world.translation.norm();
    if (predicted > 1e-9 && measured > 1e-9) scale = predicted / measured;
    if (options_.bridge_units == "depth" && b.median_depth > 0.0) {
      // The new world frame is the reference view: its points' z are their depths there.
      std::vector<double> depths;
      for (const auto& [id, p] : map_.points()) {
        if (p.position.z() > 0.0) depths.push_back(p.position.z());
      }
      if (depths.size() >= 8) scale = b.median_depth / Median(depths);
    }
    if (b.ground) {
      // The old plane's normal in the reference view (the new world frame), and the
      // reference camera's height above the old plane (old units).
      const Eigen::Vector3d up_ref = ref_in_old.rotation * b.ground->head<3>();
      const double old_height =
          b.ground->head<3>().dot(ref_in_old.Inverse().translation) + (*b.ground)[3];
      std::vector<Eigen::Vector3d> points;
      for (const auto& [id, p] : map_.points()) points.push_back(p.position);
      const std::optional<double> new_height = CameraHeightAboveGround(
          points, up_ref, options_.bridge_ground_band, options_.bridge_ground_min_points,
          options_.bridge_ground_min_share);
      MBSLAM_LOG(INFO) << log_name_ << ": bridge: camera height above the ground " << old_height
                       << " (old units), "
                       << (new_height ? std::to_string(*new_height) : std::string("no ground"))
                       << " (new units)"
                       << " against scale x" << scale;
      if (new_height && old_height > 0.0) {
        scale = old_height / *new_height;
        ground_bridged = true;
      }
    }
    metric_ = b.metric;
  }
  // X_old = ref_in_old^-1 * (scale * X_new): the new world frame is the reference camera.
  const Rigid3d old_from_new = ref_in_old.Inverse();
  map_.Rescale(scale);
  for (auto& [id, k] : map_.keyframes()) k.cam_from_world = k.cam_from_world * old_from_new.Inverse();
  for (auto& [id, p] : map_.points()) p.position = old_from_new * p.position;
  for (auto& [frame, pose] : recent_poses_) {
    pose.cam_from_world.translation *= scale;
    pose.cam_from_world = pose.cam_from_world * old_from_new.Inverse();
  }
  // The old plane is the new map's ground too when it set the units (the camera is at the
  // same height above it); a map dropped before its confirmation drops it again.
  if (ground_bridged) ground_plane_ = b.ground;
  MBSLAM_LOG(INFO) << log_name_ << ": new map continues the previous world frame (gap of "
                   << ref_frame - b.frame << " frames, scale x" << scale << ")";
}

bool SlamSystem::NeedKeyframe(const SlamFrame& frame, const std::unordered_map<int64_t, int>& labels) const {
  const int64_t since = frame.frame_index - last_keyframe_frame_;
  if (since < options_.keyframe_min_frames) return false;
  // A keyframe observes the static tracks: an image with fewer than a pose needs makes
  // none (just after a relocalisation the tracks are new, not yet judged, and a keyframe
  // of none would hold back the next one, which triangulates against it, for
  // keyframe_max_frames).
  int static_tracks = 0;
  for (const SlamObservation& o : frame.observations) {
    auto it = labels.find(o.track_id);
    static_tracks += it != labels.end() && it->second == 0;
  }
  if (static_tracks < options_.min_tracking_inliers) return false;
  if (since >= options_.keyframe_max_frames) return true;
  if (last_inliers_ < options_.keyframe_tracked_ratio * tracked_points_at_keyframe_) return true;
  // Parallax to the last keyframe (rotation compensated, via the poses).
  const Keyframe* kf = map_.LastKeyframe();
  const std::optional<Rigid3d> cur = PoseOf(frame.frame_index);
  if (!kf || !cur) return false;
  const Eigen::Matrix3d Rk = kf->cam_from_world.RotationMatrix().transpose();
  const Eigen::Matrix3d Rc = cur->RotationMatrix().transpose();
  std::vector<double> angles;
  for (const SlamObservation& o : frame.observations) {
    auto it = kf->track_xy.find(o.track_id);
    if (it == kf->track_xy.end()) continue;
    const Eigen::Vector3d a = (Rk * it->second.homogeneous()).normalized();
    const Eigen::Vector3d b = (Rc * o.xy.homogeneous()).normalized();
    angles.push_back(std::acos(std::clamp(a.dot(b), -1.0, 1.0)));
  }
  return Median(angles) > options_.keyframe_parallax_deg * kDeg;
}

bool RotationPriorStillHolds(int known, int essential, double ratio) {
  constexpr int kAllowedMissing = 4;
  return known >= ratio * essential || essential - known <= kAllowedMissing;
}

bool SlamSystem::RotationPriorHolds(const SlamFrame& frame, const std::unordered_map<int64_t, int>& labels) const {
  if (!frame.rotation_prior) return true;
  // Against the oldest keyframe that still shares enough tracks: between neighbouring
  // keyframes the turn of a small object is a sideways step within the noise (the
  // bas-relief ambiguity); over a longer baseline it shows.
  std::vector<Eigen::Vector2d> xr, xn;
  const Keyframe* ref = nullptr;
  for (const auto& [kid, k] : map_.keyframes()) {
    if (!k.rotation_prior || k.rotation_prior->ref_id != frame.rotation_prior->ref_id) continue;
    xr.clear();
    xn.clear();
    for (const SlamObservation& o : frame.observations) {
      auto lab = labels.find(o.track_id);
      if (lab == labels.end() || lab->second != 0) continue;
      auto it = k.track_xy.find(o.track_id);
      if (it == k.track_xy.end()) continue;
      xr.push_back(it->second);
      xn.push_back(o.xy);
    }
    if (static_cast<int>(xr.size()) >= options_.init_min_points) {
      ref = &k;
      break;
    }
  }
  if (!ref) return true;  // nothing to test against: a later keyframe will tell
  const double thresh = 1.0 / frame.focal_px;
  const EssentialFit fit = FitEssential(xr, xn, thresh);
  if (!fit.ok()) return true;
  const int e_inl = fit.inliers;
  const Eigen::Matrix3d R =
      (frame.rotation_prior->cam_from_ref * ref->rotation_prior->cam_from_ref.conjugate()).toRotationMatrix();
  const std::optional<KnownRotationTranslation> kt = TranslationGivenRotation(xr, xn, R, thresh, 200);
  const int known = kt ? kt->count : 0;
  MBSLAM_LOG(DEBUG) << log_name_ << " keyframe at frame " << frame.frame_index << ": from frame "
                    << ref->frame_index << " the known rotation explains " << known
                    << " of the essential matrix's " << e_inl << " inliers";
  return RotationPriorStillHolds(known, e_inl, options_.rotation_prior_keep_inlier_ratio);
}

void SlamSystem::AddKeyframe(const SlamFrame& frame, const std::unordered_map<int64_t, int>& labels,
                             SlamMapUpdate* update) {
  if (rotation_prior_active_ && options_.rotation_prior_keep_inlier_ratio > 0.0 &&
      !RotationPriorHolds(frame, labels)) {
    rotation_prior_active_ = false;
    MBSLAM_LOG(INFO) << log_name_ << ": the body turns at frame " << frame.frame_index
                     << ": no rotation prior for the rest of this map";
  }
  const Rigid3d T = *PoseOf(frame.frame_index);
  Keyframe kf;
  kf.frame_index = frame.frame_index;
  kf.utime = frame.utime;
  kf.cam_from_world = T;
  if (frame.odom_from_cam) {
    kf.has_odometry = true;
    kf.odom_from_cam = *frame.odom_from_cam;
  }
  kf.rotation_prior = frame.rotation_prior;
  auto is_static = [&labels](int64_t track) {
    auto it = labels.find(track);
    return it != labels.end() && it->second == 0;
  };
  for (const SlamObservation& o : frame.observations) {
    if (!is_static(o.track_id)) continue;
    kf.track_xy[o.track_id] = o.xy;
    kf.track_uv[o.track_id] = o.uv;
  }
  const int64_t kid = map_.AddKeyframe(std::move(kf));
  const Keyframe& k = *map_.keyframe(kid);
  // The keyframe's image follows the keyframe itself in the adjusted trajectory.
  if (!trajectory_.empty() && trajectory_.back().utime == frame.utime) {
    trajectory_.back().anchor_keyframe = kid;
    trajectory_.back().cam_from_anchor = Rigid3d();
  }
  const double max_err = options_.triangulation_max_error_px / frame.focal_px;
  int tracked = 0, unseen = 0, degenerate = 0, low_parallax = 0, reprojection = 0, released = 0;
  for (const auto& [track, x] : k.track_xy) {
    const int64_t pid = map_.PointOfTrack(track);
    if (pid < 0 && released_tracks_.count(track)) {
      ++released;
      continue;
    }
    if (pid >= 0) {
      const MapPoint* p = map_.point(pid);
      if (ReprojectionError(T, p->position, x) <= 2.0 * max_err) {
        map_.AddObservation(pid, kid, x);
        ++tracked;
      }
      continue;
    }
    // Triangulate against the oldest keyframe (of the last few) that saw this track.
    const Keyframe* first = nullptr;
    int looked = 0;
    for (auto it = map_.keyframes().rbegin(); it != map_.keyframes().rend() && looked < 10; ++it, ++looked) {
      if (it->first == kid) continue;
      if (it->second.track_xy.count(track)) first = &it->second;
    }
    if (!first) {
      ++unseen;
      continue;
    }
    const Eigen::Vector2d& x0 = first->track_xy.at(track);
    const std::optional<Eigen::Vector3d> X = TriangulateDlt(first->cam_from_world, x0, T, x);
    if (!X) {
      ++degenerate;
      continue;
    }
    if (ParallaxAngle(first->cam_from_world, T, *X) < options_.triangulation_min_angle_deg * kDeg) {
      ++low_parallax;
      continue;
    }
    if (ReprojectionError(first->cam_from_world, *X, x0) > max_err || ReprojectionError(T, *X, x) > max_err) {
      ++reprojection;
      continue;
    }
    MapPoint p;
    p.position = *X;
    p.track_id = track;
    p.created_frame = frame.frame_index;
    p.last_seen_frame = frame.frame_index;
    p.gray = frame.mean_gray;
    const int64_t new_pid = map_.AddPoint(std::move(p));
    // Every keyframe between that saw the track and agrees gets the observation.
    for (auto& [id, other] : map_.keyframes()) {
      auto it = other.track_xy.find(track);
      if (it == other.track_xy.end()) continue;
      if (ReprojectionError(other.cam_from_world, *X, it->second) <= 2.0 * max_err) {
        map_.AddObservation(new_pid, id, it->second);
      }
    }
    update->new_point_ids.push_back(new_pid);
  }
  tracked_points_at_keyframe_ = tracked + static_cast<int>(update->new_point_ids.size());
  MBSLAM_LOG(DEBUG) << log_name_ << " keyframe at image " << frame.frame_index << ": "
                    << k.track_xy.size() << " static tracks, " << tracked << " on points, "
                    << update->new_point_ids.size() << " new points; not triangulated: " << unseen
                    << " unseen by the last keyframes, " << degenerate << " degenerate, "
                    << low_parallax << " low parallax, " << reprojection << " reprojection, "
                    << released << " released before";
  if (options_.relocalization) DescribeKeyframePoints(frame.image, kid);
  last_keyframe_frame_ = frame.frame_index;
  update->new_keyframe = true;
  update->culled_points = CullKeyframes(frame.frame_index);
}

std::optional<double> SlamSystem::EstablishMetricScale() {
  if (metric_ || !options_.use_odometry) return std::nullopt;
  // The first and the last keyframe with odometry, once they are far enough apart for
  // the ratio of the two baselines to be reliable.
  const Keyframe* first = nullptr;
  const Keyframe* last = nullptr;
  for (const auto& [id, k] : map_.keyframes()) {
    if (!k.has_odometry) continue;
    if (!first) first = &k;
    last = &k;
  }
  if (!first || first == last) return std::nullopt;
  const double odo = (last->odom_from_cam.Inverse() * first->odom_from_cam).translation.norm();
  const double slam = (last->cam_from_world * first->cam_from_world.Inverse()).translation.norm();
  if (odo < options_.metric_min_baseline_m || slam < 1e-9) return std::nullopt;
  MergeBundleAdjustment(true);
  const double s = odo / slam;
  map_.Rescale(s);
  if (ground_plane_) (*ground_plane_)[3] *= s;
  for (TrajectoryEntry& e : trajectory_) {
    e.cam_from_world.translation *= s;
    e.cam_from_anchor.translation *= s;
  }
  for (auto& [id, K] : retired_keyframes_) K.translation *= s;
  for (auto& [frame, pose] : recent_poses_) {
    pose.cam_from_world.translation *= s;
    pose.cam_from_anchor.translation *= s;
    pose.covariance.topLeftCorner<3, 3>() *= s * s;
    pose.covariance.topRightCorner<3, 3>() *= s;
    pose.covariance.bottomLeftCorner<3, 3>() *= s;
  }
  metric_ = true;
  MBSLAM_LOG(INFO) << log_name_ << ": metric scale from odometry (x" << s << " over a " << odo
                   << " m baseline)";
  return s;
}

int SlamSystem::CullKeyframes(int64_t frame_index) {
  int removed = 0;
  while (static_cast<int>(map_.num_keyframes()) > options_.max_keyframes) {
    auto oldest = map_.keyframes().begin();
    const int64_t id = oldest->first;
    const bool was_fixed = oldest->second.fixed;
    const std::vector<int64_t> pids = oldest->second.point_ids;
    for (int64_t pid : pids) {
      MapPoint* p = map_.point(pid);
      if (!p) continue;
      p->observations.erase(std::remove_if(p->observations.begin(), p->observations.end(),
                                           [id](const Observation& o) { return o.keyframe_id == id; }),
                            p->observations.end());
      if (p->observations.size() < 2 && p->track_id < 0) {
        map_.RemovePoint(pid);
        ++removed;
      }
    }
    if (options_.adjusted_trajectory_max_poses > 0) retired_keyframes_[id] = oldest->second.cam_from_world;
    map_.keyframes().erase(id);
    if (was_fixed && !map_.keyframes().empty()) map_.keyframes().begin()->second.fixed = true;
  }
  // Points spared above because a track still held them: once that track has died or
  // stopped matching them (a track's end is not reported to the map), nothing else would
  // remove them and a long run would keep every point it ever made.
  removed += map_.RemoveStalePoints(frame_index - options_.culled_point_max_unmatched_frames);
  return removed;
}

SlamMapUpdate SlamSystem::UpdateMap(const SlamFrame& frame, const std::unordered_map<int64_t, int>& labels) {
  SlamMapUpdate update;
  if (map_.num_keyframes() == 0) return update;
  // Segmentation feedback (sec. 4.3): a track that joined a moving object takes its
  // point out of the static map (the object starts from it); one that is merely
  // unexplained releases its point.
  for (const SlamObservation& o : frame.observations) {
    const int64_t pid = map_.PointOfTrack(o.track_id);
    if (pid < 0) continue;
    auto it = labels.find(o.track_id);
    if (it == labels.end() || it->second == 0) continue;
    if (it->second > 0) {
      update.released_points.push_back(map_.point(pid)->position);
      update.released_tracks.push_back(o.track_id);
      map_.RemovePoint(pid);
    } else {
      map_.point(pid)->released_frame = frame.frame_index;
      map_.ReleaseTrack(o.track_id);
    }
  }
  const std::optional<Rigid3d> cur = PoseOf(frame.frame_index);
  if (cur && !frame.moving_hulls_xy.empty()) {
    // Points of the recent keyframes behind a moving hull are occluded, not lost.
    std::set<int64_t> recent;
    int n = 0;
    for (auto it = map_.keyframes().rbegin(); it != map_.keyframes().rend() && n < 3; ++it, ++n) {
      recent.insert(it->second.point_ids.begin(), it->second.point_ids.end());
    }
    for (int64_t pid : recent) {
      MapPoint* p = map_.point(pid);
      if (!p || p->track_id >= 0) continue;
      const Eigen::Vector3d pc = *cur * p->position;
      if (pc.z() <= 0) continue;
      const Eigen::Vector2f xy = pc.hnormalized().cast<float>();
      bool inside = false;
      for (const auto& hull : frame.moving_hulls_xy) inside = inside || InsideConvexHull(hull, xy);
      p->occluded = inside;
    }
  }
  if (state_ != SlamState::kTracking && state_ != SlamState::kConfirming) return update;
  if (!cur) return update;
  const bool keyframe = NeedKeyframe(frame, labels);
  if (keyframe) {
    AddKeyframe(frame, labels, &update);
    update.rescaled_by = EstablishMetricScale();
  }
  // A global adjustment asked for starts before (instead of) a keyframe's local one, which
  // it covers: else, live, a local one started at every keyframe could put it off.
  if (global_ba_requested_ && state_ == SlamState::kTracking && map_.num_keyframes() >= 2 &&
      !ba_running_) {
    global_ba_requested_ = false;
    ++requested_ba_runs_;
    MBSLAM_LOG(INFO) << log_name_ << " frame " << frame.frame_index
                     << ": global bundle adjustment asked for (" << map_.num_keyframes()
                     << " keyframes, " << map_.num_points() << " points)";
    StartBundleAdjustment(/*global=*/true, /*requested=*/true);
  } else if (keyframe) {
    StartBundleAdjustment(static_cast<int>(map_.num_keyframes()) <=
                          options_.ba.global_max_keyframes);
  }
  return update;
}

BaProblem SlamSystem::ExtractBa(int window, bool global, double focal_px, bool use_odometry) const {
  BaProblem p = ExtractBaProblem(map_, window, global, focal_px, use_odometry);
  if (rotation_prior_active_) {
    p.rotation_prior_floor_rad = options_.rotation_prior_floor_rad;
    p.rotation_prior_rad_per_s = options_.rotation_prior_rad_per_s;
  }
  return p;
}

bool SlamSystem::UsesRotationPrior() const {
  return options_.rotation_prior_floor_rad > 0.0 || options_.rotation_prior_rad_per_s > 0.0;
}

std::optional<PoseRotationPrior> SlamSystem::TrackingRotationPrior(const SlamFrame& frame) const {
  if (!frame.rotation_prior || !UsesRotationPrior() || !rotation_prior_active_) return std::nullopt;
  for (auto it = map_.keyframes().rbegin(); it != map_.keyframes().rend(); ++it) {
    const Keyframe& k = it->second;
    if (!k.rotation_prior || k.rotation_prior->ref_id != frame.rotation_prior->ref_id) continue;
    // If the body did not turn: cam_from_body = (cam_from_ref * ref_from_cam_k) * cam_k_from_body.
    PoseRotationPrior prior;
    prior.cam_from_world =
        (frame.rotation_prior->cam_from_ref * k.rotation_prior->cam_from_ref.conjugate() * k.cam_from_world.rotation)
            .normalized();
    prior.sigma_rad =
        RotationPriorSigma(options_.rotation_prior_floor_rad, options_.rotation_prior_rad_per_s, frame.utime - k.utime);
    if (prior.sigma_rad <= 0.0) return std::nullopt;
    return prior;
  }
  return std::nullopt;
}

void SlamSystem::StartBundleAdjustment(bool global, bool requested, bool here_and_now) {
  BundleAdjustmentOptions ba = options_.ba;
  if (requested) {
    global = true;
    ba.max_iterations = ba.requested_max_iterations;
    ba.max_seconds = ba.requested_max_seconds;
  }
  if (!options_.background_ba || here_and_now) {
    MergeBundleAdjustment(/*wait=*/true);
    BaProblem problem = ExtractBa(options_.ba.window_keyframes, global, focal_px_, metric_ && options_.use_odometry);
    const BaSummary s = SolveBa(&problem, ba);
    ++ba_runs_;
    last_ba_seconds_ = s.seconds;
    last_ba_usable_ = s.usable;
    last_ba_requested_ = requested;
    if (s.usable) {
      ApplyBaResult(problem, options_.ba, &map_);
      RefineTrajectory();
    }
    return;
  }
  if (ba_running_) return;  // the next keyframe triggers another run
  MergeBundleAdjustment(true);
  ba_problem_ = std::make_unique<BaProblem>(
      ExtractBa(options_.ba.window_keyframes, global, focal_px_, metric_ && options_.use_odometry));
  ba_running_ = true;
  running_ba_requested_ = requested;
  ba_thread_ = std::thread([this, ba] {
    // Lower priority than the per-image loop: on a 2-core robot computer the BA must not
    // delay images (its result is merged whenever it is ready). Raising niceness is
    // always permitted; a failure only leaves the default priority.
    if (options_.background_ba_nice > 0)
      setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), options_.background_ba_nice);
    ba_summary_ = SolveBa(ba_problem_.get(), ba);
    ba_running_ = false;
  });
}

void SlamSystem::MergeBundleAdjustment(bool wait) {
  if (!ba_thread_.joinable()) return;
  if (!wait && ba_running_) return;
  ba_thread_.join();
  ++ba_runs_;
  last_ba_seconds_ = ba_summary_.seconds;
  last_ba_usable_ = ba_summary_.usable;
  last_ba_requested_ = running_ba_requested_;
  if (ba_summary_.usable && ba_problem_) {
    ApplyBaResult(*ba_problem_, options_.ba, &map_);
    RefineTrajectory();
  }
  ba_problem_.reset();
}

std::optional<RelativeMotion> SlamSystem::RelativeMotionBetween(int64_t ref, int64_t cur) const {
  auto r = recent_poses_.find(ref);
  auto n = recent_poses_.find(cur);
  if (r == recent_poses_.end() || n == recent_poses_.end() || !initialized()) return std::nullopt;
  RelativeMotion m;
  m.cam_n_from_cam_r = *PoseOf(cur) * PoseOf(ref)->Inverse();
  const Matrix6d ad = m.cam_n_from_cam_r.Adjoint();
  m.covariance = n->second.covariance + ad * r->second.covariance * ad.transpose();
  m.translation_known = m.cam_n_from_cam_r.translation.norm() > 1e-9;
  m.scale_known = true;
  m.source = RelativeMotion::Source::kSlam;
  m.fitted_to_tracks = r->second.epipolar_assisted || n->second.epipolar_assisted;
  return m;
}

const SlamSystem::DepthGrid& SlamSystem::GridFor(int64_t frame, const Rigid3d& T) const {
  auto it = depth_grids_.find(frame);
  if (it != depth_grids_.end()) return it->second;
  DepthGrid grid;
  constexpr double kCell = 0.08;
  std::set<int64_t> seen;
  int kfs = 0;
  for (auto k = map_.keyframes().rbegin(); k != map_.keyframes().rend() && kfs < 3; ++k, ++kfs) {
    for (int64_t id : k->second.point_ids) {
      if (!seen.insert(id).second) continue;
      const MapPoint* p = map_.point(id);
      if (!p) continue;
      const Eigen::Vector3d pc = T * p->position;
      if (pc.z() <= 0.0) continue;
      const Eigen::Vector2d xy = pc.hnormalized();
      const int64_t key = (static_cast<int64_t>(std::floor(xy.x() / kCell)) << 32) ^
                          (static_cast<int64_t>(std::floor(xy.y() / kCell)) & 0xffffffff);
      auto [cell, inserted] = grid.cells.try_emplace(key, pc.z(), pc.z());
      if (!inserted) {
        cell->second.first = std::min(cell->second.first, pc.z());
        cell->second.second = std::max(cell->second.second, pc.z());
      }
      ++grid.counts[key];
    }
  }
  return depth_grids_.emplace(frame, std::move(grid)).first->second;
}

DepthBound SlamSystem::DepthBoundFor(int64_t track_id, const Eigen::Vector2d& xy, int64_t frame) const {
  DepthBound bound;
  const std::optional<Rigid3d> pose = PoseOf(frame);
  if (!pose || !initialized()) return bound;
  const Rigid3d T = *pose;
  const int64_t pid = map_.PointOfTrack(track_id);
  if (pid >= 0) {
    const double z = (T * map_.point(pid)->position).z();
    if (z > 0.0) {
      return DepthBound{z * (1.0 - options_.depth_bound_margin), z * (1.0 + options_.depth_bound_margin)};
    }
  }
  // The frustum around the ray: depths of the map points of the last keyframes that
  // project within one grid cell (~0.08 normalised units, ~40 px) of it.
  const DepthGrid& grid = GridFor(frame, T);
  constexpr double kCell = 0.08;
  const int64_t cx = static_cast<int64_t>(std::floor(xy.x() / kCell));
  const int64_t cy = static_cast<int64_t>(std::floor(xy.y() / kCell));
  double zmin = std::numeric_limits<double>::max(), zmax = 0.0;
  int n = 0;
  for (int64_t dx = -1; dx <= 1; ++dx) {
    for (int64_t dy = -1; dy <= 1; ++dy) {
      const int64_t key = ((cx + dx) << 32) ^ ((cy + dy) & 0xffffffff);
      auto it = grid.cells.find(key);
      if (it == grid.cells.end()) continue;
      zmin = std::min(zmin, it->second.first);
      zmax = std::max(zmax, it->second.second);
      n += grid.counts.at(key);
    }
  }
  if (n >= 3) {
    bound.z_min = zmin / options_.frustum_bound_factor;
    bound.z_max = zmax * options_.frustum_bound_factor;
  }
  return bound;
}

}  // namespace mbslam
