#include "services/perception/slam/object_reconstruction.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <utility>

#include "common/util/logging.h"
#include "common/util/statistics.h"

namespace mbslam {

std::vector<Eigen::Vector3d> MaturePoints(const Map& map, int min_keyframes) {
  std::vector<Eigen::Vector3d> out;
  for (int64_t pid : MaturePointIds(map, min_keyframes)) out.push_back(map.point(pid)->position);
  return out;
}

std::vector<int64_t> MaturePointIds(const Map& map, int min_keyframes) {
  const size_t need = std::min(static_cast<size_t>(std::max(1, min_keyframes)), map.num_keyframes());
  std::vector<int64_t> out;
  out.reserve(map.num_points());
  for (const auto& [pid, p] : map.points()) {
    if (p.observations.size() >= need) out.push_back(pid);
  }
  return out;
}

namespace {

std::vector<size_t> AllIndices(size_t n) {
  std::vector<size_t> all(n);
  std::iota(all.begin(), all.end(), 0);
  return all;
}

template <typename T>
std::vector<T> Select(const std::vector<T>& items, const std::vector<size_t>& indices) {
  std::vector<T> out;
  out.reserve(indices.size());
  for (size_t i : indices) out.push_back(items[i]);
  return out;
}

// The indices of the finite points.
std::vector<size_t> FiniteIndices(const std::vector<Eigen::Vector3d>& points) {
  std::vector<size_t> finite;
  finite.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (points[i].allFinite()) finite.push_back(i);
  }
  return finite;
}

// The per-coordinate median of the points.
Eigen::Vector3d MedianCentre(const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> coords[3];
  for (const Eigen::Vector3d& p : points) {
    for (int a = 0; a < 3; ++a) coords[a].push_back(p[a]);
  }
  return Eigen::Vector3d(Median(coords[0]), Median(coords[1]), Median(coords[2]));
}

}  // namespace

std::vector<size_t> LargestClusterIndices(const std::vector<Eigen::Vector3d>& points, double link_factor) {
  const size_t n = points.size();
  if (link_factor <= 0.0 || n < 8) return AllIndices(n);
  std::vector<double> nearest(n, std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const double d = (points[i] - points[j]).norm();
      nearest[i] = std::min(nearest[i], d);
      nearest[j] = std::min(nearest[j], d);
    }
  }
  const double link = link_factor * Median(nearest);
  if (!(link > 0.0)) return AllIndices(n);  // half the points or more duplicated: no scale to link by
  // Connected components under links of at most `link` (depth-first).
  std::vector<int> component(n, -1);
  std::vector<size_t> sizes;
  for (size_t seed = 0; seed < n; ++seed) {
    if (component[seed] >= 0) continue;
    const int c = static_cast<int>(sizes.size());
    std::vector<size_t> stack{seed};
    component[seed] = c;
    size_t count = 0;
    while (!stack.empty()) {
      const size_t i = stack.back();
      stack.pop_back();
      ++count;
      for (size_t j = 0; j < n; ++j) {
        if (component[j] < 0 && (points[i] - points[j]).norm() <= link) {
          component[j] = c;
          stack.push_back(j);
        }
      }
    }
    sizes.push_back(count);
  }
  const int largest = static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  // Only a minority is left out: without a cluster of most points there is no body to
  // tell apart from the rest.
  if (2 * sizes[static_cast<size_t>(largest)] < n) return AllIndices(n);
  std::vector<size_t> kept;
  kept.reserve(sizes[static_cast<size_t>(largest)]);
  for (size_t i = 0; i < n; ++i) {
    if (component[i] == largest) kept.push_back(i);
  }
  return kept;
}

std::vector<Eigen::Vector3d> LargestCluster(const std::vector<Eigen::Vector3d>& points, double link_factor) {
  return Select(points, LargestClusterIndices(points, link_factor));
}

std::vector<size_t> CompactIndices(const std::vector<Eigen::Vector3d>& points, double max_spread) {
  if (max_spread <= 0.0 || points.size() < 8) return AllIndices(points.size());
  const Eigen::Vector3d centre = MedianCentre(points);
  std::vector<double> distances;
  distances.reserve(points.size());
  for (const Eigen::Vector3d& p : points) distances.push_back((p - centre).norm());
  const double limit = max_spread * Median(distances);
  std::vector<size_t> kept;
  kept.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (distances[i] <= limit) kept.push_back(i);
  }
  return kept;
}

std::vector<Eigen::Vector3d> CompactPoints(const std::vector<Eigen::Vector3d>& points, double max_spread) {
  return Select(points, CompactIndices(points, max_spread));
}

std::vector<size_t> AxisCompactIndices(const std::vector<Eigen::Vector3d>& in, double max_mads,
                                       double min_mad_share) {
  if (max_mads <= 0.0 || in.size() < 8) return AllIndices(in.size());
  const std::vector<size_t> finite = FiniteIndices(in);  // a non-finite point is never published
  if (finite.size() < 8) return finite;
  const std::vector<Eigen::Vector3d> points = Select(in, finite);
  const Eigen::Vector3d centre = MedianCentre(points);
  // The body's axes from its inner half (points within the median distance of the centre):
  // the outliers this is for would tilt them.
  std::vector<double> distances;
  distances.reserve(points.size());
  for (const Eigen::Vector3d& p : points) distances.push_back((p - centre).norm());
  const double inner = Median(distances);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < points.size(); ++i) {
    if (distances[i] <= inner) cov += (points[i] - centre) * (points[i] - centre).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success) return finite;
  const Eigen::Matrix3d axes = eig.eigenvectors();  // columns
  Eigen::Vector3d med, mad;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> proj;
    for (const Eigen::Vector3d& p : points) proj.push_back(axes.col(a).dot(p - centre));
    med[a] = Median(proj);
    mad[a] = MedianAbsoluteDeviation(proj, med[a]);
  }
  // Half the points or more at one place: no spread to measure by.
  if (!(mad.maxCoeff() > 0.0)) return finite;
  // A side the tracks barely cover (points mostly on one face) has a small deviation:
  // it is floored at a share of the largest one.
  const double floor = min_mad_share * mad.maxCoeff();
  std::vector<size_t> kept;
  kept.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    bool inside = true;
    for (int a = 0; a < 3 && inside; ++a) {
      inside = std::abs(axes.col(a).dot(points[i] - centre) - med[a]) <= max_mads * std::max(mad[a], floor);
    }
    if (inside) kept.push_back(finite[i]);
  }
  // Only a minority is left out (as LargestCluster): else there is no body to measure by.
  if (2 * kept.size() < points.size()) return finite;
  return kept;
}

std::vector<size_t> DenseIndices(const std::vector<Eigen::Vector3d>& in, int neighbours, double max_mads) {
  const size_t k = static_cast<size_t>(std::max(neighbours, 1));
  if (max_mads <= 0.0 || in.size() < 8 || in.size() <= 2 * k) return AllIndices(in.size());
  const std::vector<size_t> finite = FiniteIndices(in);  // a non-finite point is never published
  const std::vector<Eigen::Vector3d> points = Select(in, finite);
  const size_t n = points.size();
  if (n < 8 || n <= 2 * k) return finite;
  // Each point's mean distance to its k nearest others.
  std::vector<double> isolation(n);
  std::vector<double> d;
  d.reserve(n - 1);
  for (size_t i = 0; i < n; ++i) {
    d.clear();
    for (size_t j = 0; j < n; ++j) {
      if (j != i) d.push_back((points[i] - points[j]).norm());
    }
    std::partial_sort(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(k), d.end());
    isolation[i] = std::accumulate(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(k), 0.0) / static_cast<double>(k);
  }
  const double median = Median(isolation);
  // Normal-scaled MAD, floored at a fifth of the median: points sampled evenly (a
  // lattice) have next to no deviation, and the slightly more isolated ones on its edges
  // would go.
  const double sigma = std::max(kMadToSigma * MedianAbsoluteDeviation(isolation, median), 0.2 * median);
  // Half the points or more at one place: no scale to measure by.
  if (!(sigma > 0.0)) return finite;
  std::vector<size_t> kept;
  kept.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (isolation[i] <= median + max_mads * sigma) kept.push_back(finite[i]);
  }
  return kept;
}

std::vector<Eigen::Vector3d> DensePoints(const std::vector<Eigen::Vector3d>& points, int neighbours,
                                         double max_mads) {
  return Select(points, DenseIndices(points, neighbours, max_mads));
}

std::vector<Eigen::Vector3d> AxisCompactPoints(const std::vector<Eigen::Vector3d>& in, double max_mads,
                                               double min_mad_share) {
  return Select(in, AxisCompactIndices(in, max_mads, min_mad_share));
}

std::vector<int64_t> BodyPointIds(const Map& map, const ObjectReconstructionOptions& options) {
  std::vector<int64_t> ids = MaturePointIds(map, options.min_point_keyframes);
  std::vector<Eigen::Vector3d> points;
  points.reserve(ids.size());
  for (int64_t pid : ids) points.push_back(map.point(pid)->position);
  // Each filter works on what the previous one kept.
  auto apply = [&](const std::vector<size_t>& kept) {
    ids = Select(ids, kept);
    points = Select(points, kept);
  };
  apply(CompactIndices(points, options.max_point_spread));
  apply(LargestClusterIndices(points, options.cluster_link_factor));
  apply(AxisCompactIndices(points, options.max_axis_mads, options.min_axis_mad_share));
  apply(DenseIndices(points, options.isolation_neighbours, options.max_isolation_mads));
  return ids;
}

SlamOptions ObjectReconstruction::ObjectSlamOptions(const ObjectReconstructionOptions& options,
                                                    const SlamOptions& slam) {
  SlamOptions s = slam;
  s.enabled = true;
  s.init_min_tracks = options.init_min_tracks;
  s.init_min_points = options.init_min_points;
  s.init_min_parallax_deg = options.init_min_parallax_deg;
  s.min_tracking_inliers = options.min_tracking_inliers;
  s.lost_frames_to_reinit = options.lost_frames_to_reinit;
  // A moving object's distance changes as much as its relative speed: the depth bridge
  // was no better on sim-multi's longest object map (trajectory 4.6 -> 4.0 %, shape
  // 53 -> 59 % of its size), so object maps keep the speed bridge.
  s.bridge_units = "speed";
  // Nor do they take epipolar-assisted poses: an object's few, short tracks are what
  // runs out, not the texture (with them, sim-multi's longest object map: trajectory
  // 4.6 -> 10.8 %, shape 53 -> 646 % of its size).
  s.hybrid_tracking = false;
  // An object's map has no ground plane (nothing gives it one); said, not left implicit.
  s.hybrid_ground_length = false;
  s.bridge_ground = false;
  s.released_tracks_stay_unmapped = options.released_tracks_stay_unmapped;
  s.max_keyframes = options.max_keyframes;
  s.keyframe_max_frames = std::max(options.keyframe_max_frames, s.keyframe_min_frames);
  s.keyframe_parallax_deg = options.keyframe_parallax_deg;
  // The object is the only motion its SLAM is given, and it covers a small part of the
  // image: no motion selection, no coverage or hull tests.
  s.init_max_motions = 1;
  s.init_min_coverage = 0.0;
  s.init_max_hull_share = 1.0;
  // An object is seen briefly and its poses are not back-filled: it starts as soon as
  // its initialisation is acceptable, without waiting for more parallax.
  s.init_good_parallax_deg = 0.0;
  // No odometry (it moves the camera, not the object), no images (guided matching), no
  // back-filled poses, no map files, no relocalisation.
  s.use_odometry = false;
  s.guided_matching = false;
  s.backfill_max_frames = 0;
  s.use_segmentation = true;
  s.map_load_path.clear();
  s.map_save_path.clear();
  s.relocalization = false;
  // Its trajectory file is written as tracked (no adjusted trajectory kept).
  s.adjusted_trajectory_max_poses = 0;
  s.rotation_prior_floor_rad = options.rotation_prior_floor_rad;
  s.rotation_prior_rad_per_s = options.rotation_prior_rad_per_s;
  s.rotation_prior_min_inlier_ratio = options.rotation_prior_min_inlier_ratio;
  s.rotation_prior_keep_inlier_ratio = options.rotation_prior_keep_inlier_ratio;
  return s;
}

ObjectReconstruction::ObjectReconstruction(const ObjectReconstructionOptions& options, const SlamOptions& slam)
    : options_(options), slam_options_(ObjectSlamOptions(options, slam)) {}

ObjectReconstruction::~ObjectReconstruction() { Flush(); }

void ObjectReconstruction::Flush() {
  for (auto& [id, e] : entries_) e.slam->Flush();
}

std::vector<ObjectReconstructionResult> ObjectReconstruction::Update(int64_t frame_index, int64_t utime,
                                                                     double focal_px,
                                                                     const std::vector<ObjectTracksInput>& objects,
                                                                     const std::optional<CameraRotationPrior>& world_rotation) {
  std::vector<ObjectReconstructionResult> results;
  if (!options_.enabled || options_.max_objects == 0) return results;
  // Forget the reconstructions of objects gone for a while.
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (frame_index - it->second.last_seen_frame > options_.forget_after_frames) {
      MBSLAM_LOG(INFO) << "object " << it->first << ": reconstruction dropped (unseen since frame "
                       << it->second.last_seen_frame << ")";
      it = entries_.erase(it);
    } else {
      ++it;
    }
  }
  // New reconstructions: the objects with most tracks, while there is room.
  std::vector<const ObjectTracksInput*> order;
  for (const ObjectTracksInput& o : objects) order.push_back(&o);
  std::stable_sort(order.begin(), order.end(), [](const ObjectTracksInput* a, const ObjectTracksInput* b) {
    return a->track_ids.size() > b->track_ids.size();
  });
  for (const ObjectTracksInput* o : order) {
    if (static_cast<int>(entries_.size()) >= options_.max_objects) break;
    if (entries_.count(o->id) || static_cast<int>(o->track_ids.size()) < options_.min_tracks) continue;
    Entry e;
    e.slam =
        std::make_unique<SlamSystem>(slam_options_, "object " + std::to_string(o->id) + " SLAM");
    e.last_seen_frame = frame_index;
    entries_.emplace(o->id, std::move(e));
    MBSLAM_LOG(INFO) << "object " << o->id << ": reconstruction started (" << o->track_ids.size() << " tracks)";
  }

  for (const ObjectTracksInput* o : order) {
    auto it = entries_.find(o->id);
    if (it == entries_.end() || o->track_ids.empty()) continue;  // no tracks: not seen
    Entry& e = it->second;
    e.last_seen_frame = frame_index;
    SlamFrame frame;
    frame.frame_index = frame_index;
    frame.utime = utime;
    frame.focal_px = focal_px;
    frame.rotation_prior = world_rotation;
    std::unordered_map<int64_t, int> labels;
    frame.observations.reserve(o->track_ids.size());
    for (size_t i = 0; i < o->track_ids.size() && i < o->xy.size(); ++i) {
      SlamObservation so;
      so.track_id = o->track_ids[i];
      so.xy = o->xy[i];
      so.uv = o->xy[i] * focal_px;
      so.body_id = 0;  // static w.r.t. the object
      so.p_static = 1.0;
      frame.observations.push_back(so);
      labels[so.track_id] = 0;
    }
    const SlamPose pose = e.slam->TrackPose(frame);
    const SlamMapUpdate update = e.slam->UpdateMap(frame, labels);
    // A map lives from its first valid pose until its SLAM starts again (a loss keeps
    // it; a re-initialisation is a new map with a new, unrelated scale).
    const SlamState state = e.slam->state();
    if (state == SlamState::kNotInitialized || state == SlamState::kInitializing) e.map_active = false;
    ObjectReconstructionResult r;
    r.id = o->id;
    if (pose.valid && !e.map_active) {
      e.map_active = true;
      e.map_id = next_map_id_++;
      ++maps_started_;
      e.last_points_frame = -1;
      MBSLAM_LOG(INFO) << "object " << o->id << ": reconstructed, map " << e.map_id << " ("
                       << e.slam->map().num_points() << " points)";
    }
    r.map_id = e.map_id;
    r.valid = pose.valid && e.map_active;
    r.num_points = static_cast<int>(e.slam->map().num_points());
    if (r.valid) {
      r.cam_from_obj = pose.cam_from_world;
      r.num_inliers = pose.num_inliers;
      r.rotation_prior = e.slam->rotation_prior_active();
      std::vector<double> z;
      for (const SlamObservation& so : frame.observations) {
        const int64_t pid = e.slam->map().PointOfTrack(so.track_id);
        if (pid < 0) continue;
        const double d = (r.cam_from_obj * e.slam->map().point(pid)->position).z();
        if (d > 0.0) z.push_back(d);
      }
      if (!z.empty()) r.median_depth = Median(z);
      if (update.new_keyframe || e.last_points_frame < 0 ||
          frame_index - e.last_points_frame >= options_.points_every_frames) {
        r.points_included = true;
        for (int64_t pid : BodyPointIds(e.slam->map(), options_)) {
          r.points.push_back(e.slam->map().point(pid)->position);
        }
        e.last_points_frame = frame_index;
      }
    }
    results.push_back(std::move(r));
  }
  return results;
}

}  // namespace mbslam
