#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_OBJECT_TRACKING_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_OBJECT_TRACKING_H_

// Tracking of every moving object the segmentation reports (thesis ch. 5-6): one
// BearingOnlyTracker and one ObjectExtentEstimator per object id, a fixed reference
// point per object carried through the images by the motion of its tracks, the cues
// from the static world (depth bound along the frustum, ground plane), the initialisation
// of a previously static object from its mapped points, prediction while the object is
// unseen, and its current and predicted volumes.
//
//   ObjectTracking objects(options);
//   ObjectFrame f;             // per image: static pose, ground plane, objects with tracks
//   const std::vector<TrackedObject>& out = objects.Update(f);
//
// Units. The options are in metres. A monocular map without odometry is up to scale, so
// the metric options are converted into map units with an estimate of the metres per map
// unit: 1 for a metric map; the known camera mounting height over the camera's height
// above the static map's ground plane (the usual monocular cue of a robot or car); else a
// configured guess. The conversion is fixed when an object's filter starts.
//
// Reference point. The filter needs the bearing of a point FIXED on the object (sec. 5.1);
// the centroid of the tracks drifts as tracks come and go. The reference starts at the
// centroid and moves with the median image displacement of the tracks seen in both
// images, pulled slightly toward the centroid and kept inside the tracks' bounding box;
// when no track carries over it restarts at the centroid (the filter's jump handling then
// moves its particles onto the new ray).
//
// Identity. The segmentation's clusters come and go (an object splits, merges, or is
// re-detected under a new id after a few images without tracks). A new segment id is
// taken to be an object already tracked when most of its tracks belonged to that object,
// or else when its centroid lies within `reid_radius_px` of where that object's filter
// predicts its reference point and the object was not seen in this image. "Most of its
// tracks" is counted against the smaller of the segment and the object's last track set
// (a cluster that took an object's tracks and gained new ones is still that object). A
// segment whose tracks belonged to an object that is also seen in this image (a split) is
// a fragment of it when it lies next to the object's other tracks and moves like them
// (with merge_new_clusters also a cluster of new tracks that does). Several segments of
// one object are one observation (their tracks merged) for one filter; a part that stops
// agreeing with the others (far from them, or moving differently) is split off and
// identified again. Outputs carry the persistent id;
// `segment_id` is the largest part's segmentation id, PersistentId() maps every segment.
//
// Algorithm layer: no LCM, no threads; deterministic (the filters are seeded by object id).

#include <cstdint>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/objects/bearing_only_tracker.h"
#include "services/perception/objects/ground_plane.h"
#include "services/perception/objects/object_extent.h"
#include "services/perception/objects/predicted_volume.h"

namespace mbslam {

struct ObjectTrackingOptions {
  bool enabled = true;  // run a filter per moving object
  // Bearing-only filter; lengths in metres, converted into map units (see above).
  BearingOnlyTrackerOptions filter;
  ObjectExtentOptions extent;  // lengths in metres
  // Camera mounting height above the ground (m); 0 = unknown. With a ground plane it
  // fixes the metres per unit of an up-to-scale map.
  double camera_height_m = 0.0;
  // Metres per map unit assumed when neither odometry nor the camera height fixes it
  // (m / unit). The SLAM sets the first map's median depth to 1 unit.
  double unit_guess_m = 5.0;
  int min_tracks = 3;                   // an object with fewer tracks in an image is not observed (count)
  int threads = 2;                      // the objects' filters run on this many threads, same result (count)
  int64_t keep_unseen_us = 1000000;     // an unseen object is predicted and reported this long (µs)
  // What is kept of an object once it is gone (its id per segment id, first-seen time,
  // person class) is forgotten this long after it was last seen (µs); >= keep_unseen_us.
  int64_t forget_after_us = 10000000;
  double depth_bound_margin = 0.2;      // the static depth behind the object, grown by this share
  double static_point_min_share = 0.3;  // previously static: share of its tracks with map points
  // The reference point is pulled toward the tracks' centroid by this share per image, so
  // that errors of the carried displacement cannot accumulate off the object [0, 1).
  double reference_centroid_pull = 0.05;
  double reid_track_share = 0.5;        // a new segment with this share of an object's tracks is it
  double reid_radius_px = 40.0;         // ... or with its centroid this near the predicted point (px)
  bool reid_near_tracks = false;        // ... measured to the segment's track box, not its centroid
  // Fragments: a segment that is part of an object also seen in this image (the
  // segmentation split it, or clustered new tracks on it apart) joins that object's
  // filter when its centroid lies this near the object's tracks and its image motion
  // agrees; a part that stops agreeing is split off again.
  bool merge_fragments = true;
  bool merge_new_clusters = false;      // ... also clusters of new tracks (none shared with the object)
  double fragment_radius_px = 30.0;     // centroid at most this far outside the object's track box (px)
  double fragment_flow_abs_px = 1.5;    // image motion difference always accepted (px per image)
  double fragment_flow_rel = 0.35;      // ... or this share of the larger image motion

  bool Check() const {
    MBSLAM_CHECK_OPTION_SECTION(filter);
    MBSLAM_CHECK_OPTION_SECTION(extent);
    MBSLAM_CHECK_OPTION_GE(camera_height_m, 0.0);
    MBSLAM_CHECK_OPTION_GT(unit_guess_m, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_tracks, 1);
    MBSLAM_CHECK_OPTION(threads >= 1 && threads <= 16);
    MBSLAM_CHECK_OPTION_GE(keep_unseen_us, 0);
    MBSLAM_CHECK_OPTION_GE(forget_after_us, keep_unseen_us);
    MBSLAM_CHECK_OPTION_GE(depth_bound_margin, 0.0);
    MBSLAM_CHECK_OPTION(static_point_min_share >= 0.0 && static_point_min_share <= 1.0);
    MBSLAM_CHECK_OPTION(reference_centroid_pull >= 0.0 && reference_centroid_pull < 1.0);
    MBSLAM_CHECK_OPTION(reid_track_share > 0.0 && reid_track_share <= 1.0);
    MBSLAM_CHECK_OPTION_GE(reid_radius_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(fragment_radius_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(fragment_flow_abs_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(fragment_flow_rel, 0.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("enabled", &enabled, "run a bearing-only filter per moving object");
    v("filter", &filter, "bearing-only particle filter (lengths in m)");
    v("extent", &extent, "object size from its tracks (lengths in m)");
    v("camera_height_m", &camera_height_m,
      "camera height above the ground, fixes metres per unit of an up-to-scale map; 0 unknown (m)");
    v("unit_guess_m", &unit_guess_m,
      "metres per map unit assumed without odometry or camera height (m/unit)");
    v("min_tracks", &min_tracks, "fewer tracks in an image: the object is not observed (count)");
    v("threads", &threads, "the objects' filters run on this many threads, same result (count)");
    v("keep_unseen_us", &keep_unseen_us, "an unseen object is predicted and reported this long (us)");
    v("forget_after_us", &forget_after_us,
      "what is kept of a gone object (id per segment, first-seen time, class) is forgotten this long after "
      "it was last seen, >= keep_unseen_us (us)");
    v("depth_bound_margin", &depth_bound_margin, "static depth behind the object grown by this share");
    v("static_point_min_share", &static_point_min_share,
      "previously static object: share of its tracks with map points");
    v("reference_centroid_pull", &reference_centroid_pull,
      "reference point pulled toward the tracks' centroid by this share per image [0, 1)");
    v("reid_track_share", &reid_track_share, "a new segment holding this share of an object's tracks is that object");
    v("reid_radius_px", &reid_radius_px,
      "... or a new segment whose centroid is this near an unseen object's predicted point (px)");
    v("reid_near_tracks", &reid_near_tracks,
      "... measured to the segment's track box instead of its centroid (large objects)");
    v("merge_fragments", &merge_fragments,
      "a segment that is a fragment of an object seen in this image joins its filter");
    v("merge_new_clusters", &merge_new_clusters,
      "... also a cluster of new tracks beside the object (no tracks shared with it)");
    v("fragment_radius_px", &fragment_radius_px, "fragment centroid at most this far outside the object's track box (px)");
    v("fragment_flow_abs_px", &fragment_flow_abs_px, "fragment image motion difference always accepted (px per image)");
    v("fragment_flow_rel", &fragment_flow_rel, "... or this share of the larger image motion");
  }
};

// One moving object as the segmentation sees it in this image.
struct ObjectObservation {
  int id = 0;
  std::vector<int64_t> track_ids;
  std::vector<Eigen::Vector2d> track_xy;  // normalised undistorted, same order
  // The static world's depths along the object's rays (camera z, map units): the object
  // lies in front of the background (depth-bound cue). Unset = unknown.
  std::optional<DepthRange> background_depth;
  // Mapped positions (world, map units) of its tracks that were static map points: a
  // previously static object (sec. 5.1.2).
  std::vector<Eigen::Vector3d> mapped_points;
  // Mean image motion of its tracks per image (normalised); unset = unknown.
  std::optional<Eigen::Vector2d> flow_xy;
  // The object's own reconstruction in this image (SfM feedback, eq. 6.3-6.4).
  struct Sfm {
    int64_t map_id = 0;
    Rigid3d cam_from_obj;       // object map units
    double median_depth = 0.0;  // camera depth of the object's points seen now (object units)
  };
  std::optional<Sfm> sfm;
};

struct ObjectFrame {
  int64_t utime = 0;
  bool pose_valid = false;   // the static world's camera pose is known
  Rigid3d cam_from_world;    // static SLAM pose (map units)
  double focal_px = 0.0;
  bool metric = false;       // the map is in metres
  std::optional<GroundPlane> ground;
  std::optional<double> rescaled_by;  // the world was rescaled by this factor in this image
  std::vector<ObjectObservation> objects;
};

struct TrackedObject {
  int id = 0;                   // persistent object id
  int segment_id = 0;           // the segmentation's id in this image (0 when unseen)
  bool seen = false;            // observed in this image
  int64_t last_seen_utime = 0;
  Eigen::Vector2d reference_xy = Eigen::Vector2d::Zero();  // bearing followed (normalised)
  BotEstimate estimate;         // reference point (world, map units)
  ObjectExtent extent;          // size and centre offset (map units)
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // box centre in the world (map units)
  std::vector<PredictedVolume> volumes;
  double metres_per_unit = 1.0;  // conversion used for this object's filter
};

struct ObjectTrackingStats {
  int64_t filters_started = 0;
  int64_t filters_from_static = 0;  // previously static objects (known depth)
  int64_t filters_dropped = 0;      // unseen for longer than keep_unseen_us
  int64_t rejected_updates = 0;     // observations a filter refused
  int64_t reference_restarts = 0;   // no track carried over: reference back at the centroid
  int64_t reidentified = 0;         // new segment ids recognised as objects already tracked
  int64_t segment_ids_forgotten = 0;  // segment id -> object id links unused for forget_after_us
  int64_t fragments_merged = 0;     // segments joined to an object seen in the same image
  int64_t fragments_split = 0;      // parts of an object that stopped agreeing with it
  int64_t sfm_observations = 0;     // images an object's reconstruction was given to its filter
  int64_t sfm_rejected = 0;         // reconstructions whose reference fell outside the object's tracks
};

class ObjectTracking {
 public:
  explicit ObjectTracking(const ObjectTrackingOptions& options);

  // One image. Returns the objects seen now and the recently seen ones (predicted), by id.
  const std::vector<TrackedObject>& Update(const ObjectFrame& frame);
  void Reset();

  // The persistent id of a segmentation id (allocated if new): for segments the filters
  // did not take in this image (too few tracks, no static pose). Call after Update.
  int PersistentId(int segment_id);
  size_t num_segment_links() const { return object_of_segment_.size(); }
  // Metres per map unit this image would use (see the header comment).
  double MetresPerUnit(const ObjectFrame& frame) const;
  const ObjectTrackingStats& stats() const { return stats_; }
  size_t size() const { return objects_.size(); }

 private:
  struct State {
    BearingOnlyTracker filter;
    ObjectExtentEstimator extent;
    std::unordered_map<int64_t, Eigen::Vector2d> last_xy;  // track id -> previous bearing
    Eigen::Vector2d reference_xy = Eigen::Vector2d::Zero();
    int64_t last_seen_utime = 0;
    int segment_id = 0;
    double metres_per_unit = 1.0;
    // SfM feedback: the reference point fixed in the object's map when the map first
    // came (its projection is then the bearing followed).
    int64_t sfm_map_id = 0;
    Eigen::Vector3d reference_in_obj = Eigen::Vector3d::Zero();
    State(const BearingOnlyTrackerOptions& f, const ObjectExtentOptions& e, int id)
        : filter(f, id), extent(e) {}
  };
  BearingOnlyTrackerOptions FilterOptionsInUnits(double metres_per_unit) const;
  ObjectExtentOptions ExtentOptionsInUnits(double metres_per_unit) const;
  Eigen::Vector2d MoveReference(State* s, const ObjectObservation& o, bool* restarted) const;
  // The persistent object id of a segment id seen for the first time, or 0 for a new object.
  // `parts`: the observations already given to each object in this image; `*fragment` is
  // set when the segment joins one of those objects.
  int Reidentify(const ObjectFrame& frame, const ObjectObservation& o,
                 const std::map<int, std::vector<const ObjectObservation*>>& parts, bool* fragment) const;
  // True when `o` agrees with the object's other parts in this image: near their tracks
  // and moving alike (see fragment_radius_px).
  bool ConsistentFragment(const ObjectFrame& frame, const ObjectObservation& o,
                          const std::vector<const ObjectObservation*>& parts, double* distance = nullptr) const;

  ObjectTrackingOptions options_;
  std::map<int, State> objects_;       // by persistent id
  struct SegmentLink {
    int id = 0;                 // persistent id
    int64_t last_utime = 0;     // image time the segment was last seen
  };
  std::map<int, SegmentLink> object_of_segment_;  // segment id -> persistent id
  int64_t utime_ = 0;                             // the latest image's time
  int next_id_ = 1;
  std::vector<TrackedObject> out_;
  ObjectTrackingStats stats_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_OBJECT_TRACKING_H_
