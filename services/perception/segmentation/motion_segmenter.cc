#include "services/perception/segmentation/motion_segmenter.h"

#include <algorithm>
#include <limits>
#include <cmath>
#include <numeric>

#include <Eigen/SVD>

#include "common/util/logging.h"
#include "services/perception/geometry/polygon.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

bool MotionSegmenter::TrackState::At(int64_t frame, Eigen::Vector2d* xy_out,
                                     Eigen::Vector2d* uv_out) const {
  // Tracks are usually observed in every image: then the frame sits at a fixed offset
  // from the newest observation.
  if (!frames.empty() && frame <= frames.back() && frames.back() - frame < static_cast<int64_t>(frames.size())) {
    const size_t k = frames.size() - 1 - static_cast<size_t>(frames.back() - frame);
    if (frames[k] == frame) {
      if (xy_out) *xy_out = xy[k];
      if (uv_out) *uv_out = uv[k];
      return true;
    }
  }
  for (size_t k = frames.size(); k-- > 0;) {
    if (frames[k] == frame) {
      if (xy_out) *xy_out = xy[k];
      if (uv_out) *uv_out = uv[k];
      return true;
    }
    if (frames[k] < frame) break;
  }
  return false;
}

MotionSegmenter::MotionSegmenter(const SegmentationOptions& options) : options_(options) {}

void MotionSegmenter::Reset() {
  tracks_.clear();
  objects_.clear();
  body_of_track_.clear();
  initialized_ = false;
  frame_ = -1;
  first_frame_ = -1;
  last_multibody_frame_ = -1;
  last_heading_.reset();
}

double MotionSegmenter::BayesUpdate(double prior, double likelihood, double parallax_px) const {
  // Static hypothesis: the fused P(static) of this image; dynamic: its complement
  // (thesis eq. 3.3 and its dynamic analogue), both with a tail for robustness, and
  // tempered for the overlapping baselines of consecutive updates.
  const double l = std::clamp(likelihood, 0.0, 1.0);
  const double e = options_.likelihood_tail;
  double log_lr = std::log((l + e) / (1.0 - l + e)) * options_.evidence_weight;
  if (log_lr > 0.0) {
    // Static evidence from a pair with little parallax is discounted (it cannot reveal
    // a degenerate mover yet), but not to nothing: a wrong early label must be able to
    // recover.
    log_lr *= std::clamp(parallax_px / options_.target_parallax_px, options_.min_static_evidence, 1.0);
  }
  const double odds = prior / (1.0 - prior) * std::exp(log_lr);
  const double p = odds / (1.0 + odds);
  return std::clamp(p, 1.0 - options_.p_clamp, options_.p_clamp);
}

int MotionSegmenter::BaseHistory() const {
  return std::max(options_.history_frames, options_.multibody_init ? options_.multibody_max_frames : 0);
}

void MotionSegmenter::UpdateHistories(const SegmenterInput& in) {
  const double prior_r2 = std::pow(options_.neighbour_prior_radius * in.width, 2);
  std::vector<const TrackState*> established;
  established.reserve(in.observations.size());
  for (const TrackObservation& o : in.observations) {
    auto it = tracks_.find(o.id);
    if (it != tracks_.end() && it->second.frames.size() >= 2) established.push_back(&it->second);
  }
  // Hulls of the confirmed moving objects, from their members' positions in this image.
  struct ObjectHull {
    int id = 0;
    std::vector<Eigen::Vector2f> hull;
    double p_static = 0.0;  // members' mean
  };
  std::vector<ObjectHull> hulls;
  if (options_.object_hull_prior) {
    std::map<int, std::pair<std::vector<Eigen::Vector2f>, double>> members;
    for (const TrackObservation& o : in.observations) {
      auto it = tracks_.find(o.id);
      if (it == tracks_.end() || !it->second.moving || it->second.object <= 0) continue;
      auto obj = objects_.find(it->second.object);
      if (obj == objects_.end() || !obj->second.confirmed ||
          in.frame_index - obj->second.first_frame < options_.object_hull_prior_min_age_frames) {
        continue;
      }
      auto& m = members[it->second.object];
      m.first.push_back(o.uv.cast<float>());
      m.second += it->second.p_static;
    }
    for (auto& [id, m] : members) {
      if (static_cast<int>(m.first.size()) < options_.min_object_tracks) continue;
      const double p = m.second / static_cast<double>(m.first.size());
      Eigen::Vector2f centroid = Eigen::Vector2f::Zero();
      for (const Eigen::Vector2f& q : m.first) centroid += q;
      centroid /= static_cast<float>(m.first.size());
      std::vector<Eigen::Vector2f> hull = ConvexHull(std::move(m.first));
      const float shrink = static_cast<float>(options_.object_hull_prior_shrink);
      for (Eigen::Vector2f& q : hull) q = centroid + shrink * (q - centroid);
      hulls.push_back(ObjectHull{id, std::move(hull), p});
    }
  }
  for (const TrackObservation& o : in.observations) {
    auto [it, inserted] = tracks_.try_emplace(o.id);
    TrackState& t = it->second;
    if (inserted) {
      t.id = o.id;
      const Eigen::Vector2f uv = o.uv.cast<float>();
      const auto hull = std::find_if(hulls.begin(), hulls.end(),
                                     [&](const ObjectHull& h) { return InsideConvexHull(h.hull, uv); });
      if (hull != hulls.end()) {
        t.p_static = std::clamp(0.5 + 0.8 * (hull->p_static - 0.5), 0.05, 0.95);
        t.moving = t.p_static < options_.static_leave;
        if (t.moving) t.object = hull->id;
      } else {
        // Prior from established neighbours: features appear on movers too.
        double sum = 0.0;
        int count = 0;
        for (const TrackState* n : established) {
          if ((n->uv.back() - o.uv).squaredNorm() <= prior_r2) {
            sum += n->p_static;
            ++count;
          }
        }
        if (count >= 3) t.p_static = std::clamp(0.5 + 0.8 * (sum / count - 0.5), 0.05, 0.95);
        t.moving = t.p_static < options_.static_leave;
      }
    }
    t.frames.push_back(in.frame_index);
    t.xy.push_back(o.xy);
    t.uv.push_back(o.uv);
    t.last_frame = in.frame_index;
    const int keep = std::max(BaseHistory(), options_.long_baseline_frames + 1);
    while (static_cast<int>(t.frames.size()) > keep) {
      t.frames.erase(t.frames.begin());
      t.xy.erase(t.xy.begin());
      t.uv.erase(t.uv.begin());
    }
  }
  for (auto it = tracks_.begin(); it != tracks_.end();) {
    if (in.frame_index - it->second.last_frame > options_.history_frames) it = tracks_.erase(it);
    else ++it;
  }
}

std::optional<RelativeMotion> MotionSegmenter::WorldMotion(const SegmenterInput& in, int64_t ref, bool use_heading,
                                                          bool* replaced) {
  if (replaced) *replaced = false;
  std::optional<RelativeMotion> given;
  if (in.world_motion) given = in.world_motion(ref, in.frame_index);
  // Checked for the reference image only (`replaced` given: the other pairs are shorter,
  // their own estimate less certain); a map's motion only (odometry is a measurement of
  // its own, with its noise in the envelope), and not when it was itself fitted to the
  // tracks' epipolar geometry.
  if (given && (!replaced || options_.world_check_trigger <= 0.0 || !given->translation_known ||
                given->source != RelativeMotion::Source::kSlam || given->fitted_to_tracks)) {
    return given;
  }
  std::vector<Eigen::Vector2d> xr, xn, xr_all, xn_all;
  for (const TrackObservation& o : in.observations) {
    const TrackState& t = tracks_.at(o.id);
    Eigen::Vector2d x;
    if (!t.At(ref, &x)) continue;
    xr_all.push_back(x);
    xn_all.push_back(o.xy);
    if (t.p_static >= options_.world_min_p_static) {
      xr.push_back(x);
      xn.push_back(o.xy);
    }
  }
  // The caller's motion, checked on the tracks believed static (too few: taken as it is).
  int given_inliers = 0;
  if (given) {
    if (static_cast<int>(xr.size()) < options_.world_min_tracks) return given;
    const double threshold = options_.two_view.ransac_threshold_px / in.focal_px;
    const Eigen::Matrix3d E = Hat(given->cam_n_from_cam_r.translation) * given->cam_n_from_cam_r.RotationMatrix();
    for (size_t i = 0; i < xr.size(); ++i) given_inliers += std::abs(EpipolarDistance(E, xr[i], xn[i])) <= threshold;
    if (given_inliers >= (1.0 - options_.world_check_trigger) * static_cast<double>(xr.size())) return given;
  }
  // Until the static world is established, the dominant motion of all tracks is it.
  if (!given && (!initialized_ || static_cast<int>(xr.size()) < options_.world_min_tracks)) {
    xr = std::move(xr_all);
    xn = std::move(xn_all);
  }
  RelativeMotion motion;
  std::vector<uint8_t> inliers;
  const Eigen::Vector3d* heading = use_heading && last_heading_ ? &*last_heading_ : nullptr;
  if (!EstimateRelativeMotion(xr, xn, in.focal_px, options_.two_view, &motion, &inliers, heading).ok()) {
    return given;
  }
  if (given) {
    // A pure rotation explains any depth's tracks no better than the caller's motion: no
    // evidence against it.
    const int own_inliers = static_cast<int>(std::count(inliers.begin(), inliers.end(), uint8_t{1}));
    if (!motion.translation_known || given_inliers >= options_.world_check_min_ratio * own_inliers) return given;
    MBSLAM_LOG(DEBUG) << "segmentation frame " << in.frame_index << ": the world motion given for images " << ref
                      << "-" << in.frame_index << " explains " << given_inliers << " of " << xr.size()
                      << " static tracks, the two-view estimate " << own_inliers << ": the latter is used";
    if (replaced) *replaced = true;
  }
  return motion;
}

int MotionSegmenter::UpdateStaticProbabilities(const SegmenterInput& in, int64_t ref,
                                               const RelativeMotion& motion) {
  const std::vector<MotionSample> samples = MotionSigmaPoints(motion);
  StaticLikelihoodOptions likelihood = options_.likelihood;
  if (likelihood.envelope_combine == "max_odometry") {
    likelihood.envelope_combine = motion.source == RelativeMotion::Source::kOdometry ? "max" : "mean";
  }
  // The pair's ground plane, from the tracks believed static, in the motion's units.
  std::optional<PairGroundPlane> ground;
  if (options_.pair_ground.enabled && options_.likelihood.use_fvb && motion.translation_known &&
      (options_.pair_ground.with_map || !motion.scale_known)) {
    std::vector<Eigen::Vector2d> xr, xn;
    for (const TrackObservation& o : in.observations) {
      const TrackState& t = tracks_.at(o.id);
      Eigen::Vector2d x;
      if (t.moving || t.p_static < options_.world_min_p_static || !t.At(ref, &x)) continue;
      xr.push_back(x);
      xn.push_back(o.xy);
    }
    ground = FitPairGroundPlane(xr, xn, motion.cam_n_from_cam_r.RotationMatrix(), motion.cam_n_from_cam_r.translation,
                                in.focal_px, options_.likelihood.sigma_px, options_.pair_ground);
  }
  // With a plane the translation's units are those of the bounds; the caller's bounds
  // are in them only if the motion said so.
  const bool scale_known = motion.scale_known || ground.has_value();
  for (const TrackObservation& o : in.observations) {
    TrackState& t = tracks_.at(o.id);
    Eigen::Vector2d x_r;
    if (!t.At(ref, &x_r)) continue;
    DepthBound depth = in.depth_bound && motion.scale_known ? in.depth_bound(o.id, x_r, ref) : DepthBound();
    if (ground) depth = CapDepthByGround(*ground, x_r, depth, options_.pair_ground);
    const StaticLikelihood lik =
        ComputeStaticLikelihood(x_r, o.xy, samples, motion.translation_known, scale_known,
                                depth, in.focal_px, likelihood);
    t.p_static = BayesUpdate(t.p_static, lik.p_static, lik.parallax_px);
    t.epipolar_px = lik.epipolar_px;
    t.p_fvb = lik.p_fvb;
    if (t.moving && t.p_static >= options_.static_enter) t.moving = false;
    else if (!t.moving && t.p_static < options_.static_leave) t.moving = true;
  }
  return ground ? ground->inliers : 0;
}

int MotionSegmenter::UpdateLongBaseline(const SegmenterInput& in, int64_t ref) {
  if (options_.long_baseline_frames <= 0 || !options_.likelihood.use_fvb || !in.world_motion) return 0;
  const int64_t n = in.frame_index;
  const double lag = static_cast<double>(std::max<int64_t>(1, n - ref));
  // Candidate references, oldest first, each at least min_ratio times the image's lag back.
  std::vector<int64_t> refs;
  for (int64_t r = std::max(first_frame_, n - options_.long_baseline_frames);
       static_cast<double>(n - r) >= options_.long_baseline_min_ratio * lag; r += options_.long_baseline_step) {
    refs.push_back(r);
  }
  if (refs.empty()) return 0;
  struct Judged {
    TrackState* t;
    double p_fvb;
  };
  struct Pair {
    bool tried = false;
    std::optional<RelativeMotion> motion;
    std::vector<MotionSample> samples;
    std::vector<Judged> judged;
    int failed = 0;  // judged tracks whose flow breaks the bound (epipolar test passed)
  };
  std::map<int64_t, Pair> pairs;
  StaticLikelihoodOptions likelihood = options_.likelihood;
  for (const TrackObservation& o : in.observations) {
    TrackState& t = tracks_.at(o.id);
    if (t.moving) continue;
    // The oldest candidate the track was observed in.
    int64_t r = -1;
    Eigen::Vector2d x_r;
    for (int64_t c : refs) {
      if (t.At(c, &x_r)) {
        r = c;
        break;
      }
    }
    if (r < 0) continue;
    Pair& pair = pairs[r];
    if (!pair.tried) {
      pair.tried = true;
      // Only a motion with a known scale (SLAM, odometry): the bound needs depths in its units.
      std::optional<RelativeMotion> m = in.world_motion(r, n);
      if (m && m->translation_known && m->scale_known) {
        pair.samples = MotionSigmaPoints(*m);
        pair.motion = std::move(m);
      }
    }
    if (!pair.motion) continue;
    likelihood.envelope_combine = options_.likelihood.envelope_combine == "max_odometry"
                                      ? (pair.motion->source == RelativeMotion::Source::kOdometry ? "max" : "mean")
                                      : options_.likelihood.envelope_combine;
    const DepthBound depth = in.depth_bound ? in.depth_bound(o.id, x_r, r) : DepthBound();
    const StaticLikelihood lik = ComputeStaticLikelihood(x_r, o.xy, pair.samples, true, true, depth, in.focal_px,
                                                         likelihood);
    // The degenerate case only: the epipolar constraint holds and the flow breaks the bound.
    if (lik.alpha > 0.5) continue;
    pair.judged.push_back(Judged{&t, lik.p_fvb});
    pair.failed += lik.p_fvb < 0.5;
  }
  int judged = 0;
  for (auto& [r, pair] : pairs) {
    // A degenerate mover is a minority of the tracks believed static: when many of them
    // break the bound at once, the long motion or its depth bounds are wrong (drift,
    // approximate intrinsics), not the world.
    if (pair.judged.size() < static_cast<size_t>(options_.world_min_tracks) ||
        pair.failed > options_.long_baseline_max_fail_share * static_cast<double>(pair.judged.size())) {
      continue;
    }
    judged += static_cast<int>(pair.judged.size());
    const double e = options_.likelihood_tail;
    for (const Judged& j : pair.judged) {
      if (j.p_fvb >= 0.5) continue;
      TrackState& t = *j.t;
      const double log_lr = std::log((j.p_fvb + e) / (1.0 - j.p_fvb + e)) * options_.long_baseline_weight;
      const double odds = t.p_static / (1.0 - t.p_static) * std::exp(log_lr);
      t.p_static = std::clamp(odds / (1.0 + odds), 1.0 - options_.p_clamp, options_.p_clamp);
      if (t.p_static < options_.static_leave) t.moving = true;
    }
  }
  return judged;
}

void MotionSegmenter::UpdateObjectModels(const SegmenterInput& in, int64_t ref) {
  for (auto& [id, obj] : objects_) {
    obj.motion.reset();
    if (!obj.confirmed) continue;
    std::vector<Eigen::Vector2d> xr, xn;
    std::vector<int64_t> ids;
    for (const TrackObservation& o : in.observations) {
      const TrackState& t = tracks_.at(o.id);
      Eigen::Vector2d x;
      if (t.object != id || !t.moving || !t.At(ref, &x)) continue;
      xr.push_back(x);
      xn.push_back(o.xy);
      ids.push_back(o.id);
    }
    if (static_cast<int>(xr.size()) < options_.min_model_tracks) continue;
    RelativeMotion m;
    std::vector<uint8_t> inliers;
    // Bounded: at a low inlier ratio an adaptive RANSAC runs to its maximum every image
    // (tens of ms per object); a failed estimate only skips this image's membership update.
    TwoViewOptions two_view = options_.two_view;
    two_view.ransac_max_iterations = std::min(two_view.ransac_max_iterations, options_.object_model_max_iterations);
    if (!EstimateRelativeMotion(xr, xn, in.focal_px, two_view, &m, &inliers).ok()) continue;
    obj.motion = m;
  }
  // Membership by the likelihood w.r.t. each modelled object: members that do not
  // fit leave, moving unassigned tracks that fit join.
  for (auto& [id, obj] : objects_) {
    if (!obj.motion) continue;
    const std::vector<MotionSample> samples = MotionSigmaPoints(*obj.motion);
    for (const TrackObservation& o : in.observations) {
      TrackState& t = tracks_.at(o.id);
      if (!t.moving || (t.object != 0 && t.object != id)) continue;
      Eigen::Vector2d x_r;
      if (!t.At(ref, &x_r)) continue;
      const StaticLikelihood lik = ComputeStaticLikelihood(
          x_r, o.xy, samples, obj.motion->translation_known, false, DepthBound(), in.focal_px,
          options_.likelihood);
      auto [pit, inserted] = t.p_object.try_emplace(id, 0.5);
      pit->second = BayesUpdate(pit->second, lik.p_static, lik.parallax_px);
      if (t.object == id && pit->second < options_.static_leave) t.object = 0;
      else if (t.object == 0 && pit->second >= options_.static_enter) t.object = id;
    }
  }
}

namespace {

struct UnionFind {
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  size_t Find(size_t x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void Union(size_t a, size_t b) {
    a = Find(a);
    b = Find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);
  }
  std::vector<size_t> parent;
};

}  // namespace

void MotionSegmenter::ClusterUnexplained(const SegmenterInput& in, int64_t ref) {
  // Candidates: moving tracks with a flow over the lag (or at least one image).
  struct Candidate {
    TrackState* t;
    Eigen::Vector2d uv;
    Eigen::Vector2d flow;  // px per image
  };
  std::vector<Candidate> cands;
  for (const TrackObservation& o : in.observations) {
    TrackState& t = tracks_.at(o.id);
    if (!t.moving) {
      t.object = 0;
      continue;
    }
    if (options_.multibody_keep_objects && t.multibody_object > 0 && objects_.count(t.multibody_object)) {
      // Grouped by the multi-view initialisation: that verdict stands over proximity.
      t.object = t.multibody_object;
      objects_[t.object].last_frame = in.frame_index;
      continue;
    }
    Eigen::Vector2d uv_ref;
    int64_t span = in.frame_index - ref;
    if (!t.At(ref, nullptr, &uv_ref)) {
      if (t.frames.size() < 2) continue;
      uv_ref = t.uv[t.uv.size() - 2];
      span = in.frame_index - t.frames[t.frames.size() - 2];
    }
    cands.push_back(Candidate{&t, o.uv, (o.uv - uv_ref) / static_cast<double>(std::max<int64_t>(1, span))});
  }
  const size_t n = cands.size();
  const double radius2 = std::pow(options_.cluster_radius * in.width, 2);
  const double lag = static_cast<double>(options_.lag_frames);
  UnionFind uf(n);
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const Candidate& a = cands[i];
      const Candidate& b = cands[j];
      const double d2 = (a.uv - b.uv).squaredNorm();
      if (d2 > radius2) continue;
      // Motion coherence: similar flow over the lag...
      const double df = (a.flow - b.flow).norm() * lag;
      const double fmax = std::max(a.flow.norm(), b.flow.norm()) * lag;
      if (df > std::max(options_.coherence_abs_px, options_.coherence_rel * fmax)) continue;
      // ...and a pair distance that changes slowly over the shared history.
      double sum = 0.0, sum2 = 0.0;
      int count = 0;
      const size_t kept = a.t->frames.size();
      for (size_t k = kept - std::min(kept, static_cast<size_t>(BaseHistory())); k < kept; ++k) {
        Eigen::Vector2d uv_b;
        if (!b.t->At(a.t->frames[k], nullptr, &uv_b)) continue;
        const double d = (a.t->uv[k] - uv_b).norm();
        sum += d;
        sum2 += d * d;
        ++count;
      }
      if (count >= 3) {
        const double mean = sum / count;
        const double var = std::max(0.0, sum2 / count - mean * mean);
        if (std::sqrt(var) > options_.distance_std_px + options_.distance_std_rel * mean) continue;
      }
      uf.Union(i, j);
    }
  }
  std::map<size_t, std::vector<size_t>> components;
  for (size_t i = 0; i < n; ++i) components[uf.Find(i)].push_back(i);

  // Largest components first, so that when an object splits the bigger part keeps the id.
  std::vector<std::vector<size_t>> comps;
  for (auto& [root, members] : components) comps.push_back(std::move(members));
  std::sort(comps.begin(), comps.end(), [](const auto& a, const auto& b) { return a.size() > b.size(); });

  std::map<int, bool> claimed;
  for (const auto& members : comps) {
    if (static_cast<int>(members.size()) < options_.min_object_tracks) {
      // Too small for an object: members of a confirmed object keep it (the object may
      // be partly occluded); others stay unassigned.
      for (size_t m : members) {
        TrackState* t = cands[m].t;
        auto it = objects_.find(t->object);
        if (it == objects_.end() || !it->second.confirmed) t->object = 0;
      }
      continue;
    }
    // Identity by majority of previous memberships; merges take the oldest id.
    std::map<int, int> votes;
    for (size_t m : members) {
      if (cands[m].t->object > 0 && objects_.count(cands[m].t->object)) ++votes[cands[m].t->object];
    }
    int id = 0;
    int best = 0;
    for (const auto& [oid, v] : votes) {
      if (claimed.count(oid)) continue;
      if (v > best || (v == best && oid < id)) {
        best = v;
        id = oid;
      }
    }
    if (id == 0 || best * 4 < static_cast<int>(members.size())) {
      id = next_object_id_++;
      ObjectState obj;
      obj.id = id;
      obj.first_frame = in.frame_index;
      objects_[id] = obj;
    }
    claimed[id] = true;
    ObjectState& obj = objects_[id];
    obj.last_frame = in.frame_index;
    ++obj.confirmations;
    if (obj.confirmations >= options_.confirm_frames) obj.confirmed = true;
    for (size_t m : members) cands[m].t->object = id;
    // Objects fully absorbed by this component are merged into it.
    for (const auto& [oid, v] : votes) {
      if (oid != id && v * 2 >= static_cast<int>(members.size()) / 4 && !claimed.count(oid)) {
        if (objects_[oid].confirmed && objects_[oid].first_frame < obj.first_frame) {
          obj.first_frame = objects_[oid].first_frame;
        }
      }
    }
  }
  // Objects that lost all members this image age out.
  for (auto it = objects_.begin(); it != objects_.end();) {
    const ObjectState& obj = it->second;
    const bool seen = claimed.count(obj.id) > 0;
    if (!seen && (!obj.confirmed || in.frame_index - obj.last_frame > options_.object_timeout_frames)) {
      for (auto& [tid, t] : tracks_) {
        if (t.object == obj.id) t.object = 0;
      }
      it = objects_.erase(it);
    } else {
      ++it;
    }
  }
}

int64_t MotionSegmenter::EarliestReference(const SegmenterInput& in) const {
  int64_t oldest = in.frame_index;
  for (const TrackObservation& o : in.observations) {
    oldest = std::min(oldest, tracks_.at(o.id).frames.front());
  }
  return std::max(oldest, in.frame_index - options_.history_frames + 1);
}

int64_t MotionSegmenter::ChooseReference(const SegmenterInput& in) const {
  // The nearest image at least lag_frames back in which the static tracks had moved
  // target_parallax_px (median image displacement), else the oldest one kept: a longer
  // baseline makes both constraints, and the flow bound above all, more decisive.
  const int64_t earliest = EarliestReference(in);
  int64_t ref = std::max(earliest, in.frame_index - options_.lag_frames);
  for (; ref > earliest; --ref) {
    std::vector<double> disp;
    for (const TrackObservation& o : in.observations) {
      const TrackState& t = tracks_.at(o.id);
      Eigen::Vector2d uv;
      if (t.moving || !t.At(ref, nullptr, &uv)) continue;
      disp.push_back((o.uv - uv).norm());
    }
    if (disp.size() < 8) break;
    std::nth_element(disp.begin(), disp.begin() + disp.size() / 2, disp.end());
    if (disp[disp.size() / 2] >= options_.target_parallax_px) break;
  }
  return ref;
}

bool MotionSegmenter::MultibodyInitialize(const SegmenterInput& in) {
  const int64_t n = in.frame_index;
  const int64_t window = std::min<int64_t>(options_.multibody_max_frames, n - first_frame_ + 1);
  if (window < options_.multibody_min_frames) return false;
  const int64_t start = n - window + 1;
  // Tracks observed in every frame of the window (histories are consecutive per track
  // only when they have no gaps; check the count and the first frame).
  std::vector<const TrackState*> complete;
  for (const TrackObservation& o : in.observations) {
    const TrackState& t = tracks_.at(o.id);
    if (t.frames.size() < static_cast<size_t>(window)) continue;
    const size_t first = t.frames.size() - static_cast<size_t>(window);
    if (t.frames[first] != start) continue;
    complete.push_back(&t);
  }
  if (static_cast<int>(complete.size()) < options_.multibody_min_tracks) return false;
  std::sort(complete.begin(), complete.end(),
            [](const TrackState* a, const TrackState* b) { return a->id < b->id; });
  auto column = [&](const TrackState* t) {
    Eigen::VectorXd y(2 * window);
    const size_t first = t->frames.size() - static_cast<size_t>(window);
    for (int64_t f = 0; f < window; ++f) {
      y[2 * f] = t->uv[first + static_cast<size_t>(f)].x();
      y[2 * f + 1] = t->uv[first + static_cast<size_t>(f)].y();
    }
    return y;
  };
  // Deterministic subsample: every s-th track by id.
  const size_t stride = (complete.size() + options_.multibody_max_tracks - 1) / options_.multibody_max_tracks;
  std::vector<const TrackState*> sample;
  for (size_t i = 0; i < complete.size(); i += std::max<size_t>(1, stride)) sample.push_back(complete[i]);
  Eigen::MatrixXd Y(2 * window, static_cast<Eigen::Index>(sample.size()));
  for (size_t c = 0; c < sample.size(); ++c) Y.col(static_cast<Eigen::Index>(c)) = column(sample[c]);
  int k = 1;
  const std::vector<int> sample_labels = ClusterTrajectories(Y, 0, options_.multibody, &k);
  if (k <= 1) return true;  // one motion: nothing to add to the per-image evidence

  // Every complete track joins the group whose subspace explains it best.
  const int dim = options_.multibody.subspace_dimension;
  const std::vector<AffineSubspace> subspaces = FitGroupSubspaces(Y, sample_labels, k, dim, 1);
  // Groups too small to be objects are absorbed by the best-fitting larger group.
  std::vector<bool> usable(static_cast<size_t>(k));
  for (int g = 0; g < k; ++g) {
    usable[static_cast<size_t>(g)] = subspaces[static_cast<size_t>(g)].members >= std::max(dim + 2, options_.min_object_tracks);
  }
  if (std::none_of(usable.begin(), usable.end(), [](bool u) { return u; })) return false;
  std::map<int, std::vector<TrackState*>> groups;
  for (const TrackState* tc : complete) {
    const Eigen::VectorXd y = column(tc);
    int best = -1;
    double best_r = std::numeric_limits<double>::max();
    for (int g = 0; g < k; ++g) {
      if (!usable[static_cast<size_t>(g)]) continue;
      const double r = subspaces[static_cast<size_t>(g)].SquaredDistance(y);
      if (r < best_r) {
        best_r = r;
        best = g;
      }
    }
    groups[best].push_back(const_cast<TrackState*>(tc));
  }
  // The static world: the group holding most of the currently static tracks (the
  // largest group at start-up).
  int world = -1;
  size_t best_score = 0;
  for (const auto& [g, members] : groups) {
    size_t score = 0;
    for (const TrackState* t : members) score += initialized_ ? (!t->moving ? 1 : 0) : 1;
    if (world < 0 || score > best_score || (score == best_score && members.size() > groups[world].size())) {
      world = g;
      best_score = score;
    }
  }
  // The grouping is evidence fused with each track's posterior (log-odds), not a
  // verdict: a track that the per-image constraints already know well is not flipped
  // by one clustering.
  auto fuse = [this](TrackState* t, double delta) {
    const double lo = std::log(t->p_static / (1.0 - t->p_static)) + delta;
    t->p_static = std::clamp(1.0 / (1.0 + std::exp(-lo)), 1.0 - options_.p_clamp, options_.p_clamp);
    if (t->moving && t->p_static >= options_.static_enter) t->moving = false;
    else if (!t->moving && t->p_static < options_.static_leave) t->moving = true;
  };
  for (auto& [tid, t] : tracks_) t.multibody_object = -1;
  for (auto& [g, members] : groups) {
    if (g == world) {
      for (TrackState* t : members) {
        t->multibody_object = 0;
        fuse(t, options_.multibody_evidence);
        if (!t->moving) t->object = 0;
      }
      continue;
    }
    // Object identity by the majority of previous memberships.
    std::map<int, int> votes;
    for (const TrackState* t : members) {
      if (t->object > 0 && objects_.count(t->object)) ++votes[t->object];
    }
    int id = 0, best = 0;
    for (const auto& [oid, v] : votes) {
      if (v > best) {
        best = v;
        id = oid;
      }
    }
    if (id == 0 || 2 * best < static_cast<int>(members.size())) {
      id = next_object_id_++;
      ObjectState obj;
      obj.id = id;
      obj.first_frame = n;
      objects_[id] = obj;
    }
    ObjectState& obj = objects_[id];
    obj.confirmed = true;
    obj.confirmations = std::max(obj.confirmations, options_.confirm_frames);
    obj.last_frame = n;
    for (TrackState* t : members) {
      fuse(t, -options_.multibody_evidence);
      t->multibody_object = id;
      if (t->moving) t->object = id;
    }
  }
  return true;
}

SegmentationResult MotionSegmenter::Update(const SegmenterInput& in) {
  frame_ = in.frame_index;
  if (first_frame_ < 0) first_frame_ = in.frame_index;
  UpdateHistories(in);
  SegmentationResult result;
  result.frame_index = in.frame_index;

  // Reference images: an adaptive lag for established tracks, the previous image for
  // young ones.
  int64_t ref = ChooseReference(in);
  if (ref < in.frame_index) {
    bool replaced = false;
    std::optional<RelativeMotion> motion = WorldMotion(in, ref, /*use_heading=*/true, &replaced);
    result.world_motion_replaced = replaced;
    if (motion && !motion->translation_known && options_.translation_lag_tries > 0) {
      const int64_t earliest = EarliestReference(in);
      int64_t lag = in.frame_index - ref;
      for (int k = 0; k < options_.translation_lag_tries; ++k) {
        lag *= 2;
        const int64_t older = std::max(earliest, in.frame_index - lag);
        if (older >= ref) break;
        std::optional<RelativeMotion> m = WorldMotion(in, older, /*use_heading=*/true);
        if (m && m->translation_known) {
          ref = older;
          motion = std::move(m);
          break;
        }
      }
    }
    if (motion) {
      // The heading the next image's two-view estimate expects: this motion's, if it
      // measured one (a heading kept over images that did not would go stale).
      if (motion->translation_known && motion->cam_n_from_cam_r.translation.norm() > 1e-12) {
        last_heading_ = motion->cam_n_from_cam_r.translation.normalized();
      }
      initialized_ = true;
      result.pair_ground_inliers = UpdateStaticProbabilities(in, ref, *motion);
      result.world_motion = motion;
      result.world_ref_frame = ref;
      if (motion->translation_known) {
        const Eigen::Vector3d e = in.K * motion->cam_n_from_cam_r.translation;
        result.epipole = e;
      }
    }
    // Tracks too young for `ref` use the previous image.
    const int64_t prev = in.frame_index - 1;
    if (ref != prev) {
      bool any_young = false;
      for (const TrackObservation& o : in.observations) {
        const TrackState& t = tracks_.at(o.id);
        if (!t.At(ref, nullptr) && t.At(prev, nullptr)) {
          any_young = true;
          break;
        }
      }
      if (any_young) {
        if (std::optional<RelativeMotion> m1 = WorldMotion(in, prev)) {
          if (options_.young_heading_from_reference && !m1->translation_known && motion &&
              motion->translation_known && motion->cam_n_from_cam_r.translation.norm() > 1e-12) {
            // Unit translation along the reference motion's direction (expressed in the
            // current camera, as the one-image motion's is); its direction uncertainty
            // is the reference's relative translation uncertainty.
            const double norm = motion->cam_n_from_cam_r.translation.norm();
            m1->cam_n_from_cam_r.translation = motion->cam_n_from_cam_r.translation / norm;
            m1->covariance.topLeftCorner<3, 3>() = motion->covariance.topLeftCorner<3, 3>() / (norm * norm);
            m1->translation_known = true;
            m1->scale_known = false;
          }
          // Only the young tracks: hide the others' reference by evaluating on a filtered set.
          SegmenterInput young = in;
          young.observations.clear();
          for (const TrackObservation& o : in.observations) {
            const TrackState& t = tracks_.at(o.id);
            if (!t.At(ref, nullptr) && t.At(prev, nullptr)) young.observations.push_back(o);
          }
          UpdateStaticProbabilities(young, prev, *m1);
        }
      }
    }
    // The map's motions over the long baseline are no better than the one the image just
    // contradicted.
    if (!result.world_motion_replaced) result.long_baseline_tracks = UpdateLongBaseline(in, ref);
    UpdateObjectModels(in, ref);
    ClusterUnexplained(in, ref);
  }
  if (options_.multibody_init &&
      (last_multibody_frame_ < 0 ||
       (options_.multibody_every_frames > 0 &&
        in.frame_index - last_multibody_frame_ >= options_.multibody_every_frames))) {
    if (MultibodyInitialize(in)) {
      last_multibody_frame_ = in.frame_index;
      initialized_ = true;
    }
  }
  result.initialized = initialized_;

  body_of_track_.clear();
  std::map<int, SegmentedObject> out_objects;
  for (const TrackObservation& o : in.observations) {
    const TrackState& t = tracks_.at(o.id);
    TrackLabel label;
    label.id = o.id;
    label.p_static = t.p_static;
    label.epipolar_px = t.epipolar_px;
    label.p_fvb = t.p_fvb;
    label.evaluated = t.frames.size() >= 2;
    const bool held = options_.multibody_init && options_.multibody_hold && t.multibody_object >= 0 &&
                      (t.multibody_object == 0 || objects_.count(t.multibody_object));
    if (held) {
      label.body_id = t.multibody_object;
    } else if (!t.moving) {
      label.body_id = label.evaluated ? 0 : -1;
    } else {
      auto it = objects_.find(t.object);
      label.body_id = (it != objects_.end() && it->second.confirmed) ? t.object : -1;
    }
    if (label.body_id > 0) {
      SegmentedObject& so = out_objects[label.body_id];
      so.track_ids.push_back(o.id);
      if (t.uv.size() >= 2) so.mean_flow_px += t.uv.back() - t.uv[t.uv.size() - 2];
    }
    body_of_track_[o.id] = label.body_id;
    result.labels.push_back(label);
  }
  for (auto& [id, so] : out_objects) {
    const ObjectState& obj = objects_.at(id);
    so.id = id;
    so.first_frame = obj.first_frame;
    so.last_frame = obj.last_frame;
    so.has_motion_model = obj.motion.has_value();
    so.mean_flow_px /= static_cast<double>(so.track_ids.size());
    std::vector<Eigen::Vector2f> pts;
    for (int64_t tid : so.track_ids) pts.push_back(tracks_.at(tid).uv.back().cast<float>());
    for (const Eigen::Vector2f& p : ConvexHull(pts)) so.hull.push_back(p.cast<double>());
    result.objects.push_back(std::move(so));
  }
  return result;
}

}  // namespace mbslam
