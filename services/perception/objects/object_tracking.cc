#include "services/perception/objects/object_tracking.h"

#include "common/util/parallel_for.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "common/util/logging.h"
#include "common/util/statistics.h"

namespace mbslam {
namespace {

Eigen::Vector2d Centroid(const std::vector<Eigen::Vector2d>& xy) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (const Eigen::Vector2d& p : xy) c += p;
  return xy.empty() ? c : Eigen::Vector2d(c / static_cast<double>(xy.size()));
}

// Axis-aligned bounds of non-empty bearings.
void Bounds(const std::vector<Eigen::Vector2d>& xy, Eigen::Vector2d* lo, Eigen::Vector2d* hi) {
  *lo = *hi = xy.front();
  for (const Eigen::Vector2d& p : xy) {
    *lo = lo->cwiseMin(p);
    *hi = hi->cwiseMax(p);
  }
}

}  // namespace

ObjectTracking::ObjectTracking(const ObjectTrackingOptions& options) : options_(options) {
  if (!options_.Check()) {
    MBSLAM_LOG(ERROR) << "ObjectTracking: invalid options, using the defaults";
    options_ = ObjectTrackingOptions();
  }
}

void ObjectTracking::Reset() {
  objects_.clear();
  object_of_segment_.clear();
  out_.clear();
}

int ObjectTracking::PersistentId(int segment_id) {
  auto it = object_of_segment_.find(segment_id);
  if (it != object_of_segment_.end()) {
    it->second.last_utime = utime_;
    return it->second.id;
  }
  const int id = next_id_++;
  object_of_segment_[segment_id] = SegmentLink{id, utime_};
  return id;
}

bool ObjectTracking::ConsistentFragment(const ObjectFrame& frame, const ObjectObservation& o,
                                        const std::vector<const ObjectObservation*>& parts,
                                        double* distance) const {
  const double f = std::max(frame.focal_px, 1e-9);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  Eigen::Vector2d flow = Eigen::Vector2d::Zero();
  double flow_weight = 0.0;
  for (const ObjectObservation* p : parts) {
    for (const Eigen::Vector2d& xy : p->track_xy) {
      lo = lo.cwiseMin(xy);
      hi = hi.cwiseMax(xy);
    }
    if (p->flow_xy) {
      flow += static_cast<double>(p->track_xy.size()) * *p->flow_xy;
      flow_weight += static_cast<double>(p->track_xy.size());
    }
  }
  if (!(lo.array() <= hi.array()).all()) return false;
  // Distance of the centroid from the object's track box (0 inside).
  const Eigen::Vector2d c = Centroid(o.track_xy);
  const Eigen::Vector2d outside = (lo - c).cwiseMax(c - hi).cwiseMax(Eigen::Vector2d::Zero());
  const double d = outside.norm();
  if (distance) *distance = d;
  if (d > options_.fragment_radius_px / f) return false;
  if (o.flow_xy && flow_weight > 0.0) {
    flow /= flow_weight;
    const double diff = (*o.flow_xy - flow).norm();
    const double scale = std::max(o.flow_xy->norm(), flow.norm());
    if (diff > std::max(options_.fragment_flow_abs_px / f, options_.fragment_flow_rel * scale)) return false;
  }
  return true;
}

int ObjectTracking::Reidentify(const ObjectFrame& frame, const ObjectObservation& o,
                               const std::map<int, std::vector<const ObjectObservation*>>& parts,
                               bool* fragment) const {
  *fragment = false;
  // Shared tracks first: a split or a re-labelled cluster keeps most of its tracks, and a
  // cluster that took most of an object's last tracks (and gained new ones) is that object.
  int best = 0;
  size_t best_shared = 0, best_known = 0;
  for (const auto& [id, s] : objects_) {
    size_t shared = 0;
    for (int64_t t : o.track_ids) shared += s.last_xy.count(t);
    if (shared > best_shared) {
      best_shared = shared;
      best_known = s.last_xy.size();
      best = id;
    }
  }
  if (best != 0 && static_cast<int>(best_shared) >= options_.min_tracks &&
      static_cast<double>(best_shared) >= options_.reid_track_share * std::min(o.track_ids.size(), best_known)) {
    auto p = parts.find(best);
    if (p == parts.end()) return best;  // re-labelled
    // A split: the object is seen in this image already; the part joins it if it agrees.
    if (options_.merge_fragments && ConsistentFragment(frame, o, p->second)) {
      *fragment = true;
      return best;
    }
    return 0;
  }
  // Else the nearest prediction of an object not seen in this image: its reference point
  // within reid_radius_px of the segment's centroid (or of its tracks' box with
  // reid_near_tracks), the nearest to the centroid.
  const Eigen::Vector2d c = Centroid(o.track_xy);
  Eigen::Vector2d lo = o.track_xy.front(), hi = o.track_xy.front();
  for (const Eigen::Vector2d& xy : o.track_xy) {
    lo = lo.cwiseMin(xy);
    hi = hi.cwiseMax(xy);
  }
  const double radius = options_.reid_radius_px / std::max(frame.focal_px, 1e-9);
  double best_d = std::numeric_limits<double>::infinity();
  best = 0;
  for (const auto& [id, s] : objects_) {
    if (parts.count(id) || !s.filter.initialized()) continue;
    const Eigen::Vector3d p = frame.cam_from_world * s.filter.Estimate().world_from_object.translation;
    if (p.z() <= 0.0) continue;
    const Eigen::Vector2d q = p.head<2>() / p.z();
    const double d = (q - c).norm();
    const double gap = options_.reid_near_tracks ? (lo - q).cwiseMax(q - hi).cwiseMax(Eigen::Vector2d::Zero()).norm() : d;
    if (gap > radius) continue;
    if (d < best_d) {
      best_d = d;
      best = id;
    }
  }
  if (best != 0 || !options_.merge_fragments || !options_.merge_new_clusters) return best;
  // Else a fragment of an object seen in this image: next to its tracks, moving alike, and
  // not larger than what is seen of it (a larger cluster beside it is another object).
  best_d = std::numeric_limits<double>::infinity();
  for (const auto& [id, ps] : parts) {
    double d = 0.0;
    size_t tracks = 0;
    for (const ObjectObservation* q : ps) tracks += q->track_ids.size();
    if (o.track_ids.size() > tracks || !objects_.count(id) || !ConsistentFragment(frame, o, ps, &d)) continue;
    if (d < best_d) {
      best_d = d;
      best = id;
    }
  }
  *fragment = best != 0;
  return best;
}

double ObjectTracking::MetresPerUnit(const ObjectFrame& frame) const {
  if (frame.metric) return 1.0;
  if (options_.camera_height_m > 0.0 && frame.ground && frame.pose_valid) {
    const Eigen::Vector3d c = frame.cam_from_world.Inverse().translation;
    const double h = frame.ground->Height(c);
    if (std::isfinite(h) && h > 1e-6) return options_.camera_height_m / h;
  }
  return options_.unit_guess_m;
}

BearingOnlyTrackerOptions ObjectTracking::FilterOptionsInUnits(double m) const {
  BearingOnlyTrackerOptions f = options_.filter;
  const double u = 1.0 / m;  // units per metre
  f.init_depth_min *= u;
  f.init_depth_max *= u;
  f.init_speed_min *= u;
  f.init_speed_max *= u;
  f.accel_sigma *= u;
  f.position_sigma *= u;
  f.min_depth *= u;
  f.ground_height_tolerance *= u;
  f.ground_height_sigma *= u;
  f.below_ground_tolerance *= u;
  f.max_ground_clearance *= u;
  f.max_object_height *= u;
  f.volumes.accel_margin *= u;
  return f;
}

ObjectExtentOptions ObjectTracking::ExtentOptionsInUnits(double m) const {
  ObjectExtentOptions e = options_.extent;
  e.min_size /= m;
  e.max_size /= m;
  return e;
}

Eigen::Vector2d ObjectTracking::MoveReference(State* s, const ObjectObservation& o, bool* restarted) const {
  std::vector<double> dx, dy;
  for (size_t i = 0; i < o.track_ids.size(); ++i) {
    auto it = s->last_xy.find(o.track_ids[i]);
    if (it == s->last_xy.end()) continue;
    dx.push_back(o.track_xy[i].x() - it->second.x());
    dy.push_back(o.track_xy[i].y() - it->second.y());
  }
  *restarted = dx.empty();
  const Eigen::Vector2d centroid = Centroid(o.track_xy);
  Eigen::Vector2d ref = centroid;
  if (!dx.empty()) {
    ref = s->reference_xy + Eigen::Vector2d(Median(dx), Median(dy));
    ref += options_.reference_centroid_pull * (centroid - ref);
    Eigen::Vector2d lo, hi;
    Bounds(o.track_xy, &lo, &hi);
    ref = ref.cwiseMax(lo).cwiseMin(hi);
  }
  s->last_xy.clear();
  for (size_t i = 0; i < o.track_ids.size(); ++i) s->last_xy[o.track_ids[i]] = o.track_xy[i];
  return ref;
}

const std::vector<TrackedObject>& ObjectTracking::Update(const ObjectFrame& frame) {
  out_.clear();
  if (!options_.enabled) return out_;
  // Links of the segments in this image stay fresh; a link unused for forget_after_us
  // goes (a segment the filters never took would otherwise keep its link for ever, and
  // Reidentify reads them all).
  utime_ = frame.utime;
  for (const ObjectObservation& o : frame.objects) {
    auto it = object_of_segment_.find(o.id);
    if (it != object_of_segment_.end()) it->second.last_utime = frame.utime;
  }
  for (auto m = object_of_segment_.begin(); m != object_of_segment_.end();) {
    if (frame.utime - m->second.last_utime > options_.forget_after_us) {
      ++stats_.segment_ids_forgotten;
      m = object_of_segment_.erase(m);
    } else {
      ++m;
    }
  }
  if (frame.rescaled_by) {
    for (auto& [id, s] : objects_) {
      s.filter.RescaleWorld(*frame.rescaled_by);
      s.extent.RescaleWorld(*frame.rescaled_by);
      s.metres_per_unit /= *frame.rescaled_by;
    }
  }
  if (!frame.pose_valid) {
    // Without the static pose no bearing can be placed in the world; filters wait.
    return out_;
  }
  std::optional<Eigen::Vector3d> up;
  if (frame.ground) up = frame.ground->normal;
  const Eigen::Vector3d up_or_camera =
      up ? *up : Eigen::Vector3d(frame.cam_from_world.Inverse().rotation * Eigen::Vector3d(0, -1, 0));

  // Association: every segment to a persistent id. Segments already known come first
  // (largest first), so that a new segment can be recognised as a fragment of them.
  std::vector<size_t> order;
  for (size_t k = 0; k < frame.objects.size(); ++k) {
    const ObjectObservation& o = frame.objects[k];
    if (!o.track_xy.empty() && o.track_xy.size() == o.track_ids.size()) order.push_back(k);
  }
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const bool ka = object_of_segment_.count(frame.objects[a].id) > 0;
    const bool kb = object_of_segment_.count(frame.objects[b].id) > 0;
    if (ka != kb) return ka;
    return frame.objects[a].track_ids.size() > frame.objects[b].track_ids.size();
  });
  std::map<int, std::vector<const ObjectObservation*>> parts;  // persistent id -> its segments now
  for (size_t k : order) {
    const ObjectObservation& o = frame.objects[k];
    int id = 0;
    auto known = object_of_segment_.find(o.id);
    if (known != object_of_segment_.end()) {
      id = known->second.id;
      auto p = parts.find(id);
      if (p != parts.end() && !(options_.merge_fragments && ConsistentFragment(frame, o, p->second))) {
        // This part no longer agrees with the object's others: identified again.
        ++stats_.fragments_split;
        MBSLAM_LOG(DEBUG) << "segment " << o.id << ": no longer agrees with object " << id << ", split off";
        id = 0;
      }
    }
    if (id == 0) {
      bool fragment = false;
      id = Reidentify(frame, o, parts, &fragment);
      if (id != 0) {
        ++(fragment ? stats_.fragments_merged : stats_.reidentified);
        MBSLAM_LOG(DEBUG) << "segment " << o.id << " (" << o.track_ids.size() << " tracks): "
                          << (fragment ? "fragment of" : "re-identified as") << " object " << id;
      }
    }
    if (id == 0) {
      id = next_id_++;
      if (GetLogLevel() <= LogLevel::kDebug) {
        std::ostringstream why;
        const Eigen::Vector2d c = Centroid(o.track_xy) * frame.focal_px;
        why << "segment " << o.id << " (" << o.track_ids.size() << " tracks at " << c.transpose() << " px, flow "
            << (o.flow_xy ? Eigen::Vector2d(*o.flow_xy * frame.focal_px) : Eigen::Vector2d::Constant(NAN)).transpose()
            << "): new object " << id << ";";
        for (const auto& [oid, st] : objects_) {
          size_t shared = 0;
          for (int64_t t : o.track_ids) shared += st.last_xy.count(t);
          double pred = NAN;
          if (st.filter.initialized()) {
            const Eigen::Vector3d p = frame.cam_from_world * st.filter.Estimate().world_from_object.translation;
            if (p.z() > 0.0) pred = (p.head<2>() / p.z() * frame.focal_px - c).norm();
          }
          double frag = NAN;
          auto pp = parts.find(oid);
          if (pp != parts.end()) ConsistentFragment(frame, o, pp->second, &frag);
          why << " [" << oid << (pp != parts.end() ? " seen" : "") << " shared " << shared << " pred " << pred
              << " px box " << frag * frame.focal_px << " px unseen " << (frame.utime - st.last_seen_utime) / 1000 << " ms]";
        }
        MBSLAM_LOG(DEBUG) << why.str();
      }
    }
    object_of_segment_[o.id] = SegmentLink{id, frame.utime};
    parts[id].push_back(&o);
  }

  std::map<int, bool> seen;  // persistent ids observed in this image
  // One object's filter step of this image (associated here, run below in parallel).
  struct FilterJob {
    int id = 0;
    State* state = nullptr;
    int segment_id = 0;
    Eigen::Vector2d ref = Eigen::Vector2d::Zero();
    std::vector<Eigen::Vector2d> track_xy;
    BotObservation observation;
    bool from_static = false;
    std::optional<Eigen::Vector3d> start_point;  // previously static: start at this point
    bool was_initialized = false;
    Status status;
  };
  std::vector<FilterJob> jobs;
  jobs.reserve(parts.size());
  for (const auto& [id, ps] : parts) {
    // One observation of the object from all its parts (the largest part first).
    ObjectObservation o = *ps.front();
    for (size_t k = 1; k < ps.size(); ++k) {
      const ObjectObservation& q = *ps[k];
      o.track_ids.insert(o.track_ids.end(), q.track_ids.begin(), q.track_ids.end());
      o.track_xy.insert(o.track_xy.end(), q.track_xy.begin(), q.track_xy.end());
      o.mapped_points.insert(o.mapped_points.end(), q.mapped_points.begin(), q.mapped_points.end());
      if (!o.sfm && q.sfm) o.sfm = q.sfm;
      if (q.background_depth) {
        // The looser bound of the parts (each is the static depth behind its centroid).
        if (!o.background_depth || q.background_depth->max > o.background_depth->max) {
          o.background_depth = q.background_depth;
        }
      }
    }
    if (static_cast<int>(o.track_xy.size()) < options_.min_tracks) continue;
    auto it = objects_.find(id);
    if (it == objects_.end()) {
      const double m = MetresPerUnit(frame);
      it = objects_.emplace(std::piecewise_construct, std::forward_as_tuple(id),
                            std::forward_as_tuple(FilterOptionsInUnits(m), ExtentOptionsInUnits(m), id))
               .first;
      it->second.metres_per_unit = m;
    }
    State& s = it->second;
    s.segment_id = o.id;
    bool restarted = false;
    Eigen::Vector2d ref = MoveReference(&s, o, &restarted);
    if (restarted && s.filter.initialized()) ++stats_.reference_restarts;
    // With the object's reconstruction the reference is a point fixed in its map, placed
    // on the followed bearing at the depth of the object's points when the map came; its
    // projection is the bearing from then on (eq. 6.3: the filter needs that point).
    std::optional<SfmObservation> sfm;
    if (o.sfm && o.sfm->median_depth > 0.0 && o.sfm->cam_from_obj.IsFinite()) {
      if (s.sfm_map_id != o.sfm->map_id) {
        s.sfm_map_id = o.sfm->map_id;
        s.reference_in_obj = o.sfm->cam_from_obj.Inverse() * (Eigen::Vector3d(ref.x(), ref.y(), 1.0) * o.sfm->median_depth);
      }
      const Eigen::Vector3d q = o.sfm->cam_from_obj * s.reference_in_obj;
      Eigen::Vector2d lo, hi;
      Bounds(o.track_xy, &lo, &hi);
      const Eigen::Vector2d margin = 0.25 * (hi - lo);
      const Eigen::Vector2d proj = q.z() > 0.0 ? Eigen::Vector2d(q.head<2>() / q.z()) : Eigen::Vector2d(1e9, 1e9);
      if (q.z() > 0.0 && (proj.array() >= (lo - margin).array()).all() && (proj.array() <= (hi + margin).array()).all()) {
        ref = proj;
        sfm = SfmObservation{o.sfm->map_id, o.sfm->cam_from_obj, s.reference_in_obj};
        ++stats_.sfm_observations;
      } else {
        // The map disagrees with the tracks: no feedback, and a new reference next time.
        s.sfm_map_id = 0;
        ++stats_.sfm_rejected;
      }
    }
    s.reference_xy = ref;

    FilterJob job;
    job.id = id;
    job.state = &s;
    job.segment_id = o.id;
    job.ref = ref;
    job.track_xy = o.track_xy;
    BotObservation& b = job.observation;
    b.utime = frame.utime;
    b.cam_from_world = frame.cam_from_world;
    b.focal_px = frame.focal_px;
    b.xy = ref;
    b.track_xy = o.track_xy;
    b.ground_plane = frame.ground;
    b.sfm = sfm;
    if (o.background_depth && std::isfinite(o.background_depth->max)) {
      b.depth_bound = DepthRange{0.0, o.background_depth->max * (1.0 + options_.depth_bound_margin)};
    }
    if (!s.filter.initialized()) {
      job.from_static =
          !o.mapped_points.empty() &&
          static_cast<double>(o.mapped_points.size()) >= options_.static_point_min_share * o.track_ids.size();
      if (job.from_static) {
        // Sec. 5.1.2: a previously static object starts at its known depth. The reference
        // bearing is the centroid: its point is placed at the mapped points' median depth.
        std::vector<double> z;
        for (const Eigen::Vector3d& p : o.mapped_points) z.push_back((frame.cam_from_world * p).z());
        const double depth = Median(z);
        if (depth > 0.0) {
          job.start_point = frame.cam_from_world.Inverse() * Eigen::Vector3d(Eigen::Vector3d(ref.x(), ref.y(), 1.0) * depth);
        }
      }
    }
    jobs.push_back(std::move(job));
  }

  // The filters of different objects share nothing (each has its own random numbers):
  // they run on options_.threads threads with the same result as one.
  ParallelFor(jobs.size(), options_.threads, [&](size_t k) {
    FilterJob& j = jobs[k];
    State& s = *j.state;
    j.was_initialized = s.filter.initialized();
    if (!j.was_initialized) {
      j.status = j.start_point ? s.filter.InitializeFromPoint(j.observation, *j.start_point)
                               : s.filter.Initialize(j.observation);
    } else {
      j.status = s.filter.Update(j.observation);
    }
    if (!j.status.ok()) return;
    const BotEstimate e = s.filter.Estimate();
    if (e.valid) s.extent.Update(frame.cam_from_world, j.track_xy, j.ref, e.depth, up_or_camera);
  });

  for (const FilterJob& j : jobs) {
    State& s = *j.state;
    if (!j.was_initialized && j.status.ok()) {
      if (j.start_point) ++stats_.filters_from_static;
      ++stats_.filters_started;
      MBSLAM_LOG(INFO) << "object " << j.id << ": filter started, " << s.metres_per_unit << " m per map unit, "
                       << (frame.ground ? "ground plane" : "no ground plane") << ", depth bound "
                       << (j.observation.depth_bound ? std::to_string(j.observation.depth_bound->max) : std::string("none"))
                       << (j.from_static ? ", previously static" : "");
    }
    if (!j.status.ok()) {
      ++stats_.rejected_updates;
      MBSLAM_LOG(DEBUG) << "object " << j.id << " (segment " << j.segment_id << "): " << j.status.message();
      continue;
    }
    s.last_seen_utime = frame.utime;
    seen[j.id] = true;
  }

  std::vector<std::pair<int, State*>> report;  // in id order
  for (auto it = objects_.begin(); it != objects_.end();) {
    State& s = it->second;
    const bool now = seen.count(it->first) > 0;
    if (!now && (!s.filter.initialized() || frame.utime - s.last_seen_utime > options_.keep_unseen_us)) {
      ++stats_.filters_dropped;
      for (auto m = object_of_segment_.begin(); m != object_of_segment_.end();) {
        m = m->second.id == it->first ? object_of_segment_.erase(m) : std::next(m);
      }
      it = objects_.erase(it);
      continue;
    }
    report.emplace_back(it->first, &s);
    ++it;
  }
  std::vector<TrackedObject> tracked(report.size());
  ParallelFor(report.size(), options_.threads, [&](size_t k) {
    const int id = report[k].first;
    State& s = *report[k].second;
    const bool now = seen.count(id) > 0;
    if (!now && s.filter.utime() < frame.utime) (void)s.filter.Predict(frame.utime, frame.ground);
    TrackedObject& t = tracked[k];
    t.id = id;
    t.seen = now;
    t.segment_id = now ? s.segment_id : 0;
    t.last_seen_utime = s.last_seen_utime;
    t.reference_xy = s.reference_xy;
    t.estimate = s.filter.Estimate();
    t.extent = s.extent.extent();
    t.center = t.estimate.world_from_object.translation + (t.extent.valid ? t.extent.center_offset : Eigen::Vector3d::Zero());
    t.volumes = s.filter.PredictVolumes(t.extent);
    // The filter's boxes surround its reference points; the object's centre is offset.
    if (t.extent.valid) {
      for (PredictedVolume& v : t.volumes) v.center += t.extent.center_offset;
    }
    t.metres_per_unit = s.metres_per_unit;
  });
  for (TrackedObject& t : tracked) {
    if (t.estimate.valid) out_.push_back(std::move(t));
  }
  return out_;
}

}  // namespace mbslam
