#ifndef MBSLAM_SERVICES_PERCEPTION_SLAM_OBJECT_RECONSTRUCTION_H_
#define MBSLAM_SERVICES_PERCEPTION_SLAM_OBJECT_RECONSTRUCTION_H_

// Reconstruction of moving objects (thesis ch. 4 applied to each moving body, sec. 4.1):
// one monocular keyframe SLAM per object chosen for reconstruction, fed only with the
// tracks segmentation assigns to that object. For the object's SLAM the object is the
// static world: it estimates cam_from_obj (the camera w.r.t. the object) and the
// object's points, in the object's own frame and its own unknown scale. The bearing-only
// tracker fuses it (SfM feedback, eq. 6.3-6.4), which gives the relative scale (sec. 6.1).
//
// Objects are chosen by their number of tracks (the largest first, at most max_objects
// at once); a reconstruction goes when its object has not been seen for
// forget_after_frames. Each (re-)initialisation starts a new map with a new map_id: its
// scale is unrelated to the previous one.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/slam/slam_system.h"

namespace mbslam {

struct ObjectReconstructionOptions {
  bool enabled = true;            // reconstruct moving objects with enough tracks
  int min_tracks = 40;            // tracks an object needs before its SLAM starts (count)
  int max_objects = 2;            // reconstructions running at once, the objects with most tracks (count)
  int forget_after_frames = 15;   // a reconstruction whose object is unseen this long is dropped (frames)
  int init_min_tracks = 30;       // the object's SLAM: tracks to start an initialisation (count)
  int init_min_points = 20;       // ... points triangulated by it (count)
  double init_min_parallax_deg = 2.0;  // ... median parallax of the two views (deg)
  int min_tracking_inliers = 12;  // ... fewer inliers = its tracking is lost (count)
  int lost_frames_to_reinit = 10; // ... frames lost before it re-initialises (its own: a quick restart splits a briefly seen object into short maps)
  int max_keyframes = 30;         // ... keyframes kept (count)
  // An object's tracks are short-lived (it is small and turns its sides): its points are
  // only triangulated between keyframes, so they come more often than the world's.
  int keyframe_max_frames = 20;   // ... a keyframe at least this often (frames)
  double keyframe_parallax_deg = 2.0;  // ... parallax to the last keyframe that triggers one (deg)
  int points_every_frames = 10;   // the object's points are output at least this often, and at its keyframes (frames)
  // An object is compact: its published points leave out those farther from the points'
  // median than this multiple of their median distance to it (points of static tracks
  // along the object's outline or of another body, depths a short baseline left
  // unconstrained). The map keeps them: they still help to resect the camera. 0 = all.
  double max_point_spread = 4.0;
  // Published points: those seen from at least this many keyframes (all keyframes while
  // the map has fewer). A point two views of a small object triangulated lies anywhere
  // along the line of sight. 3 against 1, lockstep seed 1: sim-multi's 8 reconstructions,
  // shape rmse median 15.7 -> 7.7 % of the size (four maps now within 1.5 %);
  // sim-crossing's 145 -> 109 %; sim-following's car 83.9 -> 84.6 %. 5 against 3 (with
  // the rotation prior below): sim-multi's longest map 8.0 -> 0.75 %, sim-crossing's
  // 39 -> 35 %.
  int min_point_keyframes = 5;
  // ... and only those of the largest cluster: points joined by links of at most this
  // multiple of their median nearest-neighbour distance (0 = all). A body that moves
  // along with the object in its epipolar plane (a car passing behind a person walking
  // the same way) is triangulated as a consistent, static-looking group beside the
  // object's own points, which compactness alone keeps. Only a minority is left out (a
  // largest cluster under half the points: all are published). 3, lockstep, seeds
  // 1 / 2 / 3: sim-crossing's shape 35 / 31 / 28 -> 13 / 16 / 28 %, sim-multi's longest
  // map 0.75 / 65 / 22 -> 0.76 / 65 / 10 % (47 % on seed 2 without the majority rule).
  double cluster_link_factor = 3.0;
  // ... and only those within max_axis_mads median absolute deviations of the median along
  // each of the body's principal axes (of its inner half; a deviation is floored at
  // min_axis_mad_share of the largest one). Another body moving in parallel with the
  // object (its relative motion a translation along the same direction: the same
  // essential matrix) joins its segment and is triangulated at a wrong depth, off the
  // object's thin side, where a radius about the median does not reach it.
  // 3, lockstep, seeds 1 / 2: sim-crossing's shape rmse 13.4 / 15.9 -> 4.0 / 14.2 % of the
  // size (2: 2.9 / 8.4 %, but a quarter of sim-multi's points go, against 7 % with 3);
  // sim-multi's maps, sim-following's and sim-previously_static's unchanged.
  double max_axis_mads = 3.0;          // (0 = off)
  double min_axis_mad_share = 0.25;
  // ... and only those not isolated: a point whose mean distance to its
  // isolation_neighbours nearest others is more than max_isolation_mads (normal-scaled)
  // median absolute deviations, floored at a fifth of the median, above the median of
  // that distance is left out (the statistical outlier removal of point-cloud
  // libraries, with robust statistics). A feature of another body or of the background
  // that kept with the object for a while is triangulated off its surface, alone or in a
  // pair, which the single-link cluster joins to the body when it lies within a few
  // spacings of it. Lockstep, longest map, shape rmse (% of size): sim-crossing seed 1
  // 2.9 -> 2.2 (34 -> 32 points), seed 2 9.9 -> 2.3 (30 -> 26 points); seed 3, sim-multi
  // seeds 1-3, sim-following seeds 1-3 and sim-previously_static seeds 1-3 within 0.05
  // points.
  int isolation_neighbours = 4;     // (count)
  double max_isolation_mads = 3.0;  // (0 = off)
  // SfM feedback (eq. 6.3-6.4): the reconstruction drives the object's bearing-only
  // filter and gives its relative scale. Off by default: on sim-crossing it moved the
  // position error from 0.057 to 0.063 and the 1 s hit rate from 0.86 to 0.82.
  bool feedback_to_tracker = false;
  // The camera's own rotation (the static world's SLAM) as a prior on the object's SLAM:
  // an object that does not turn keeps R_cam_from_obj * R_cam_from_world^T. A small object
  // spans a few degrees of the view, where a sideways translation and a turn about the
  // vertical look alike (the bas-relief ambiguity). The prior fixes the initial views'
  // rotation (only the translation is fitted) and holds the rotation between keyframes
  // (bundle adjustment) and from the last keyframe (tracking) within floor + rate * time.
  // A map takes the prior only if, at its initialisation, the known rotation explains as
  // many correspondences as a free essential matrix (rotation_prior_min_inlier_ratio),
  // and keeps it while it explains rotation_prior_keep_inlier_ratio of them at each new
  // keyframe. People and vehicles mostly keep their heading, so the prior is
  // tight: 0.002 rad + 0.005 rad/s against the former 0.005 rad + 0.05 rad/s, which let
  // a straight walker's map turn within its slack. Lockstep, seed 1, longest map
  // (trajectory / shape rmse, % of path / size), with min_point_keyframes 5 and the
  // cluster filter: sim-crossing 15.4 / 104 -> 0.98 / 13; sim-following 18.6 / 39 ->
  // 0.33 / 0.74; sim-previously_static 6.0 / 24 -> 0.56 / 0.37; sim-multi (walkers on
  // ellipses, up to 1.8 rad/s) 4.9 / 26 -> 1.35 / 0.76, but the median over its 8 maps
  // 4.1 / 45 -> 9.3 / 39 (short maps of turning cars keep the prior). Seeds 2 / 3:
  // sim-crossing 21 / 28 -> 1.05 / 3.8 and 330 / 1100 -> 16 / 85. (Both 0 = no prior.) Fed only
  // the person's tracks by the truth masks (a one-off harness; tracking.object_features
  // 50), sim-crossing's map was 23 / 242 without the prior, 6.0 / 55 with the loose one
  // and 0.53 / 4.2 with the tight one: the prior, more than the segmentation, was the
  // limit.
  double rotation_prior_floor_rad = 0.002;
  double rotation_prior_rad_per_s = 0.005;
  // The gate: the share of a free essential matrix's inliers the known rotation must
  // explain at the map's initialisation (a turning object explains fewer). 0.9: sim-multi
  // shape median 109 %; 0.97: 42 %; 1.0: 17 %, sim-crossing the same for all three
  // (measured with the loose prior).
  double rotation_prior_min_inlier_ratio = 1.0;
  // ... and keeps it while, at each new keyframe, the known rotation from the oldest
  // keyframe that shares init_min_points tracks explains this share of a free essential
  // matrix's inliers, or all but 4 of them (0 = the prior stays for the map's life): an
  // object that walks straight, then turns, and whose turn shows over a long baseline
  // only. Without the 4-track allowance sim-crossing's straight walker lost the prior on
  // 16 of 19 (its map 0.98 -> 14.7 % trajectory); as it is, two sim-multi maps drop it,
  // and the unit scene's walker turning 60 deg/s drops it after about 50 deg.
  double rotation_prior_keep_inlier_ratio = 0.9;
  // A track released from its point as an outlier of the object's pose is not
  // triangulated again on that map (SlamOptions::released_tracks_stay_unmapped): a feature on the
  // object's outline (half the object, half what is behind it) slides along it, and was
  // made a new wrong point at each keyframe. Lockstep, longest map, trajectory / shape
  // (% of path / size), seeds 1 / 2 / 3: sim-crossing 0.98 / 4.0, 1.05 / 14.2, 29 / 715 ->
  // 0.89 / 2.9, 0.97 / 9.9, 6.5 / 743 (seed 3's longest map is still of a segment that
  // mixes the walker, the car behind him, the robot and static features); sim-multi
  // seed 1 8.1 / 42 -> 8.4 / 28, seeds 2 / 3 and
  // sim-following / sim-previously_static within +-0.4 points. For the world's map (the
  // SLAM option) it was worse: TartanAir five starts ATE 0.83 -> 1.88 %.
  bool released_tracks_stay_unmapped = true;

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(min_tracks, 8);
    MBSLAM_CHECK_OPTION_GE(max_objects, 0);
    MBSLAM_CHECK_OPTION_GE(forget_after_frames, 1);
    MBSLAM_CHECK_OPTION_GE(init_min_tracks, 8);
    MBSLAM_CHECK_OPTION_GE(init_min_points, 8);
    MBSLAM_CHECK_OPTION_GT(init_min_parallax_deg, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_tracking_inliers, 6);
    MBSLAM_CHECK_OPTION_GE(lost_frames_to_reinit, 1);
    MBSLAM_CHECK_OPTION_GE(max_keyframes, 3);
    MBSLAM_CHECK_OPTION_GE(keyframe_max_frames, 3);
    MBSLAM_CHECK_OPTION_GT(keyframe_parallax_deg, 0.0);
    MBSLAM_CHECK_OPTION_GE(points_every_frames, 1);
    MBSLAM_CHECK_OPTION(max_point_spread == 0.0 || max_point_spread > 1.0);
    MBSLAM_CHECK_OPTION_GE(min_point_keyframes, 1);
    MBSLAM_CHECK_OPTION(cluster_link_factor == 0.0 || cluster_link_factor >= 1.0);
    MBSLAM_CHECK_OPTION(max_axis_mads == 0.0 || max_axis_mads >= 1.0);
    MBSLAM_CHECK_OPTION(min_axis_mad_share > 0.0 && min_axis_mad_share <= 1.0);
    MBSLAM_CHECK_OPTION_GE(isolation_neighbours, 1);
    MBSLAM_CHECK_OPTION(max_isolation_mads == 0.0 || max_isolation_mads >= 1.0);
    MBSLAM_CHECK_OPTION_GE(rotation_prior_floor_rad, 0.0);
    MBSLAM_CHECK_OPTION_GE(rotation_prior_rad_per_s, 0.0);
    MBSLAM_CHECK_OPTION(rotation_prior_min_inlier_ratio >= 0.0 && rotation_prior_min_inlier_ratio <= 1.0);
    MBSLAM_CHECK_OPTION(rotation_prior_keep_inlier_ratio >= 0.0 && rotation_prior_keep_inlier_ratio <= 1.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("enabled", &enabled, "reconstruct moving objects with enough tracks (their own SLAM)");
    v("min_tracks", &min_tracks, "tracks an object needs before its SLAM starts (count)");
    v("max_objects", &max_objects, "reconstructions at once, the objects with most tracks (count)");
    v("forget_after_frames", &forget_after_frames, "a reconstruction whose object is unseen this long goes (frames)");
    v("init_min_tracks", &init_min_tracks, "object SLAM: tracks to start an initialisation (count)");
    v("init_min_points", &init_min_points, "object SLAM: points the initialisation must triangulate (count)");
    v("init_min_parallax_deg", &init_min_parallax_deg, "object SLAM: median parallax of the initial views (deg)");
    v("min_tracking_inliers", &min_tracking_inliers, "object SLAM: fewer inliers = lost (count)");
    v("lost_frames_to_reinit", &lost_frames_to_reinit, "object SLAM: frames lost before re-initialising (frames)");
    v("max_keyframes", &max_keyframes, "object SLAM: keyframes kept (count)");
    v("keyframe_max_frames", &keyframe_max_frames, "object SLAM: a keyframe at least this often (frames)");
    v("keyframe_parallax_deg", &keyframe_parallax_deg, "object SLAM: parallax to the last keyframe that triggers one (deg)");
    v("points_every_frames", &points_every_frames, "object points output at least this often, and at its keyframes (frames)");
    v("max_point_spread", &max_point_spread,
      "object points published only within this multiple of their median distance to their median; 0 = all");
    v("min_point_keyframes", &min_point_keyframes,
      "object points published once seen from this many keyframes (all keyframes while the map has fewer)");
    v("cluster_link_factor", &cluster_link_factor,
      "object points published only in their largest cluster: links up to this multiple of the median nearest-neighbour distance (0 = all)");
    v("max_axis_mads", &max_axis_mads,
      "object points published only within this many median absolute deviations along the body's principal axes (0 = all)");
    v("min_axis_mad_share", &min_axis_mad_share, "... each axis's deviation floored at this share of the largest");
    v("isolation_neighbours", &isolation_neighbours, "object points: neighbours of the isolation distance (count)");
    v("max_isolation_mads", &max_isolation_mads,
      "object points published only if their mean distance to their nearest neighbours is within this many normal-scaled MADs (1.4826 MAD, at least a fifth of the median) above the median (0 = all)");
    v("feedback_to_tracker", &feedback_to_tracker, "the reconstruction drives the object's bearing-only filter (SfM feedback) and relative scale");
    v("rotation_prior_floor_rad", &rotation_prior_floor_rad,
      "the camera's rotation (world SLAM) as a prior on the object's: noise floor (rad; both 0 = off)");
    v("rotation_prior_rad_per_s", &rotation_prior_rad_per_s,
      "... plus this much turning of the object per second (rad/s)");
    v("rotation_prior_min_inlier_ratio", &rotation_prior_min_inlier_ratio,
      "a map takes the prior only if the known rotation explains this share of a free E's inliers at its initialisation");
    v("rotation_prior_keep_inlier_ratio", &rotation_prior_keep_inlier_ratio,
      "... and keeps it while the known rotation explains this share of a free E's inliers at each keyframe (0 = always)");
    v("released_tracks_stay_unmapped", &released_tracks_stay_unmapped,
      "object SLAM: a track released from its point as a pose outlier is not triangulated again on that map");
  }
};

// The tracks of one moving object in one image (an object without tracks counts as unseen).
struct ObjectTracksInput {
  int id = 0;                          // the object's id (stable across images)
  std::vector<int64_t> track_ids;
  std::vector<Eigen::Vector2d> xy;     // normalised, same order
};

// One object's reconstruction in one image.
struct ObjectReconstructionResult {
  int id = 0;
  int64_t map_id = 0;              // identifies the map (and its scale); new at every initialisation
  bool valid = false;              // cam_from_obj is known for this image
  Rigid3d cam_from_obj;            // object map units
  int num_inliers = 0;
  bool rotation_prior = false;     // the map holds the object's rotation to the camera's (it has not turned)
  int num_points = 0;              // points in the object's map
  double median_depth = 0.0;       // median camera depth of the object's points seen in this image (object units)
  bool points_included = false;    // `points` holds the map (at a keyframe or every points_every_frames)
  std::vector<Eigen::Vector3d> points;  // the object's points, object frame (object map units)
};

// The points within `max_spread` times their median distance to their coordinate-wise
// median (all of them for fewer than 8 points or max_spread 0).
std::vector<Eigen::Vector3d> CompactPoints(const std::vector<Eigen::Vector3d>& points, double max_spread);

// The positions of the map's points seen from at least min(min_keyframes, keyframes in
// the map) keyframes: a point triangulated from two views of a small object is poorly
// placed along the line of sight until a third view confirms it.
std::vector<Eigen::Vector3d> MaturePoints(const Map& map, int min_keyframes);

// The points of the largest cluster, joined by links of at most link_factor times the
// points' median nearest-neighbour distance; all of them for fewer than 8 points,
// link_factor 0, a median of 0 (duplicates) or a largest cluster of under half the
// points. O(n^2): object maps hold hundreds of points.
std::vector<Eigen::Vector3d> LargestCluster(const std::vector<Eigen::Vector3d>& points, double link_factor);
// The points within max_mads median absolute deviations of the median along each
// principal axis of the inner half (deviations floored at min_mad_share of the largest);
// non-finite points are left out. Fewer than 8 points or max_mads 0: all; half the
// points or more at one place (no spread), or a majority outside: all finite ones.
std::vector<Eigen::Vector3d> AxisCompactPoints(const std::vector<Eigen::Vector3d>& points, double max_mads,
                                               double min_mad_share);
// The points not isolated: each point's mean distance to its `neighbours` nearest others
// within max_mads normal-scaled median absolute deviations (at least a fifth of the median)
// above the median of that distance; non-finite points are left out. max_mads 0 or at
// most max(7, 2 * neighbours) points: all; the same for the finite ones, or half of them
// at one place: all finite ones.
std::vector<Eigen::Vector3d> DensePoints(const std::vector<Eigen::Vector3d>& points, int neighbours,
                                         double max_mads);
// The same four filters as indices into `points` (ascending).
std::vector<size_t> CompactIndices(const std::vector<Eigen::Vector3d>& points, double max_spread);
std::vector<size_t> LargestClusterIndices(const std::vector<Eigen::Vector3d>& points, double link_factor);
std::vector<size_t> AxisCompactIndices(const std::vector<Eigen::Vector3d>& points, double max_mads,
                                       double min_mad_share);
std::vector<size_t> DenseIndices(const std::vector<Eigen::Vector3d>& points, int neighbours, double max_mads);
// MaturePoints as map point ids.
std::vector<int64_t> MaturePointIds(const Map& map, int min_keyframes);
// The ids of the map's points taken for the body, its published points: mature
// (min_point_keyframes), then compact (max_point_spread), then the largest cluster
// (cluster_link_factor), then within the body's axes (max_axis_mads), then not isolated
// (max_isolation_mads).
std::vector<int64_t> BodyPointIds(const Map& map, const ObjectReconstructionOptions& options);

class ObjectReconstruction {
 public:
  // `slam` is the static world's SLAM configuration; each object's SLAM uses it with the
  // object settings above (no odometry, no guided matching, one motion, no coverage).
  ObjectReconstruction(const ObjectReconstructionOptions& options, const SlamOptions& slam);
  ~ObjectReconstruction();

  // `world_rotation`: the camera's rotation w.r.t. the static world in this image, when
  // the world's SLAM has a pose (the objects' rotation prior).
  std::vector<ObjectReconstructionResult> Update(int64_t frame_index, int64_t utime, double focal_px,
                                                 const std::vector<ObjectTracksInput>& objects,
                                                 const std::optional<CameraRotationPrior>& world_rotation = std::nullopt);
  // Waits for the back-end threads (end of a replay).
  void Flush();
  size_t num_reconstructions() const { return entries_.size(); }
  int64_t maps_started() const { return maps_started_; }

  // The SLAM configuration an object's reconstruction runs with.
  static SlamOptions ObjectSlamOptions(const ObjectReconstructionOptions& options, const SlamOptions& slam);

 private:
  struct Entry {
    std::unique_ptr<SlamSystem> slam;
    int64_t map_id = 0;
    bool map_active = false;   // map_id names the current map
    int64_t last_seen_frame = 0;
    int64_t last_points_frame = -1;
  };
  const ObjectReconstructionOptions options_;
  const SlamOptions slam_options_;
  std::map<int, Entry> entries_;
  int64_t next_map_id_ = 1;
  int64_t maps_started_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SLAM_OBJECT_RECONSTRUCTION_H_
