#ifndef MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_MOTION_SEGMENTER_H_
#define MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_MOTION_SEGMENTER_H_

// Incremental multibody motion segmentation (thesis ch. 3). Every image:
//  1. the static world's motion between a reference image and this one comes from
//     SLAM or odometry when available, else from a robust two-view estimate on the
//     tracks currently believed static (the dominant motion at start-up);
//  2. each track's P(static) is updated by recursive Bayes with the fused
//     epipolar-envelope / Flow-Vector-Bound likelihood;
//  3. objects with enough tracks get their own motion model, and tracks are
//     (re)assigned by the same likelihood w.r.t. that model;
//  4. unexplained tracks are clustered by spatial proximity and motion coherence into
//     new objects; objects appear, split, merge and leave.
// Works on tracks alone (no images): the tracks-only entry point for Hopkins-style data.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>

#include "common/config/options.h"
#include "services/perception/segmentation/ground_bound.h"
#include "services/perception/segmentation/relative_motion.h"
#include "services/perception/segmentation/static_likelihood.h"
#include "services/perception/segmentation/subspace_clustering.h"

namespace mbslam {

struct SegmentationOptions {
  StaticLikelihoodOptions likelihood;
  TwoViewOptions two_view;
  // The ground plane of each image pair (the static tracks' inverse depths under the
  // world motion): rays that meet it get a depth bound for the Flow Vector Bound, also
  // before a map exists.
  PairGroundOptions pair_ground;
  int object_model_max_iterations = 50;   // RANSAC iterations of each moving object's two-view model (count; per image and object)
  SubspaceClusteringOptions multibody;  // multi-view multibody initialisation (sec. 3.4)
  bool multibody_init = false;      // (re)initialise bodies by affine subspace clustering of the track window (near-affine views, e.g. Hopkins; not for forward motion)
  int multibody_min_frames = 10;    // window length needed for the first initialisation (frames)
  int multibody_max_frames = 30;    // longest window used (frames)
  int multibody_every_frames = 10;  // re-initialisation period (frames); 0 = only once
  int multibody_max_tracks = 250;   // tracks clustered (subsampled beyond; the rest join by residual) (count)
  int multibody_min_tracks = 20;    // fewer complete tracks: no initialisation (count)
  double multibody_evidence = 10.0; // log-odds added for / against static by a multibody grouping (beyond the clamp: the grouping decides)
  bool multibody_keep_objects = true;  // moving tracks grouped by the last multibody initialisation keep that object instead of being re-clustered by proximity
  bool multibody_hold = true;       // tracks grouped by the last multibody initialisation report that body until the next one (the per-image two-view evidence does not relabel them in between)
  int lag_frames = 3;               // reference image at least this many images back (frames)
  int history_frames = 16;          // per-track history kept; the reference is at most this far back (frames)
  double target_parallax_px = 12.0; // the reference goes back until static tracks moved this much (px)
  double evidence_weight = 0.5;     // exponent on each image's likelihood ratio (overlapping windows)
  double likelihood_tail = 0.05;    // added to both hypotheses' likelihoods: one bad match is not proof
  double min_static_evidence = 0.25;  // static evidence of a low-parallax pair keeps at least this weight
  double p_clamp = 0.98;            // posterior clamp, lets a label switch within a few images
  double static_enter = 0.6;        // P(static) to become static again
  double static_leave = 0.4;        // P(static) below which a track is moving
  double neighbour_prior_radius = 0.06;  // new tracks take their prior from neighbours within this (fraction of width)
  // A new track inside the convex hull of a confirmed moving object's members (as
  // observed in this image) takes its prior from those members and joins the object,
  // instead of averaging over every neighbour (the background around a small object
  // outnumbers it); its own evidence then confirms or releases it.
  bool object_hull_prior = false;
  int object_hull_prior_min_age_frames = 10; // ... only objects segmented for at least this many images (frames)
  double object_hull_prior_shrink = 0.7;     // ... the hull scaled about its members' centroid by this (fraction)
  int min_object_tracks = 6;        // tracks needed for an object (count)
  int confirm_frames = 2;           // a cluster must persist this long to become an object (frames)
  int object_timeout_frames = 15;   // an object unseen this long is removed (frames)
  double cluster_radius = 0.12;     // spatial proximity for clustering (fraction of image width)
  double coherence_abs_px = 2.0;    // flow difference always accepted as coherent (px over the lag)
  double coherence_rel = 0.35;      // flow difference accepted relative to the flow (fraction)
  double distance_std_px = 1.5;     // allowed std of a pair's distance over the history (px)
  double distance_std_rel = 0.05;   // ... plus this fraction of the distance
  int min_model_tracks = 10;        // an object gets its own motion model above this (count)
  int world_min_tracks = 15;        // static tracks needed to estimate the world motion (count)
  double world_min_p_static = 0.25; // tracks at least this likely static take part in the world-motion RANSAC
                                    // (below the moving threshold, so mislabelled static tracks can come back)
  // A map's world motion (SLAM's poses) is checked against the image: when it explains
  // (epipolar distance within two_view.ransac_threshold_px) fewer of the tracks believed
  // static than world_check_min_ratio times the segmenter's own two-view estimate does,
  // the two-view estimate judges this image instead (counted as world_motion_replaced).
  // A map's poses are consistent with the map, not necessarily with the image: with
  // approximate intrinsics (uncalibrated video) static tracks of large parallax the map
  // does not hold sit pixels off their epipolar lines and turn moving one after the other
  // (DAVIS parkour: 50 % of its features labelled moving, the background's median
  // epipolar distance 5-14 px). Only the reference pair is checked, and not odometry
  // motions (a measurement of their own, with their noise in the envelope; checked, they
  // made sim-robot_odometry's scale error 1.06 -> 1.24 %) nor SLAM's epipolar-assisted
  // poses (fitted to corner-like tracks already: a two-view estimate over every track,
  // edges that slide included, outvoted them on TartanAir's tile walls and the five-start
  // ATE rose 0.73 -> 1.21 %). The two-view estimate runs only when the map's motion leaves
  // more than world_check_trigger of those tracks unexplained (0 = never check). The
  // young tracks' one-image pairs keep the map's motion (checked too, they made TartanAir
  // worse: the one-image two-view estimate is the less certain one).
  double world_check_trigger = 0.1;    // unexplained share of the static tracks that starts the check [0, 1]
  double world_check_min_ratio = 0.8;  // the map's inliers below this share of the two-view's: replaced (0, 1]
  // Young tracks are judged over one image. A translating camera often moves too little
  // in one image for its translation to be measured, and the image-to-image motion comes
  // out as a pure rotation, under which every near static point's parallax is an error.
  // When the longer reference motion has a known translation, its direction is lent to
  // the one-image motion (steady heading): young tracks are then judged against the
  // epipole, with their depth free.
  bool young_heading_from_reference = true;
  // The reference image is chosen by image displacement, which a rotating camera has
  // plenty of before its translation shows: when the two-view motion to it comes out as
  // a pure rotation, references twice, four times ... as far back (within
  // history_frames) are tried this many times for one whose translation is measurable
  // (a pure rotation would make every near static point's parallax look like motion).
  int translation_lag_tries = 2;
  // Long-baseline Flow Vector Bound. A mover that keeps inside its epipolar plane (a
  // robot followed along the camera's own direction) looks like a static point farther
  // away; its flow falls short of the least flow the depth bound allows by an amount
  // that grows with the baseline, but over the usual reference lag that shortfall stays
  // within the bound's noise margin. Tracks believed static are therefore also judged
  // against an image up to long_baseline_frames back, with the world motion and depth
  // bounds of SLAM or odometry (scale known; never a two-view estimate): where the
  // epipolar test passes and the flow breaks the bound there, the evidence counts
  // against static. Only evidence against: the short pairs already count the static
  // evidence of the same observations.
  int long_baseline_frames = 48;         // oldest reference (frames back); 0 = off
  int long_baseline_step = 8;            // references tried every this many images (frames)
  double long_baseline_min_ratio = 2.0;  // used only this many times farther back than the image's reference (ratio)
  double long_baseline_weight = 0.5;     // exponent on the long pair's likelihood ratio
  double long_baseline_max_fail_share = 0.1;  // a pair whose flow bound fails for more of its static tracks is not used (fraction)

  bool Check() const {
    MBSLAM_CHECK_OPTION_SECTION(likelihood);
    MBSLAM_CHECK_OPTION_SECTION(two_view);
    MBSLAM_CHECK_OPTION_SECTION(pair_ground);
    MBSLAM_CHECK_OPTION_GE(object_model_max_iterations, 1);
    MBSLAM_CHECK_OPTION_SECTION(multibody);
    MBSLAM_CHECK_OPTION_GE(multibody_min_frames, 2);
    MBSLAM_CHECK_OPTION_GE(multibody_max_frames, multibody_min_frames);
    MBSLAM_CHECK_OPTION_GE(multibody_every_frames, 0);
    MBSLAM_CHECK_OPTION_GE(multibody_max_tracks, multibody_min_tracks);
    MBSLAM_CHECK_OPTION_GE(multibody_min_tracks, 8);
    MBSLAM_CHECK_OPTION_GT(multibody_evidence, 0.0);
    MBSLAM_CHECK_OPTION_GE(lag_frames, 1);
    MBSLAM_CHECK_OPTION(translation_lag_tries >= 0 && translation_lag_tries <= 8);
    MBSLAM_CHECK_OPTION_GT(history_frames, lag_frames);
    MBSLAM_CHECK_OPTION_GT(target_parallax_px, 0.0);
    MBSLAM_CHECK_OPTION(evidence_weight > 0.0 && evidence_weight <= 1.0);
    MBSLAM_CHECK_OPTION(likelihood_tail > 0.0 && likelihood_tail < 1.0);
    MBSLAM_CHECK_OPTION(min_static_evidence >= 0.0 && min_static_evidence <= 1.0);
    MBSLAM_CHECK_OPTION(p_clamp > 0.5 && p_clamp < 1.0);
    MBSLAM_CHECK_OPTION(static_leave <= static_enter);
    MBSLAM_CHECK_OPTION_GE(min_object_tracks, 2);
    MBSLAM_CHECK_OPTION_GE(confirm_frames, 1);
    MBSLAM_CHECK_OPTION_GE(object_timeout_frames, 1);
    MBSLAM_CHECK_OPTION_GT(cluster_radius, 0.0);
    MBSLAM_CHECK_OPTION_GE(min_model_tracks, 8);
    MBSLAM_CHECK_OPTION_GE(world_min_tracks, 8);
    MBSLAM_CHECK_OPTION(world_check_trigger >= 0.0 && world_check_trigger <= 1.0);
    MBSLAM_CHECK_OPTION(world_check_min_ratio > 0.0 && world_check_min_ratio <= 1.0);
    MBSLAM_CHECK_OPTION_GE(object_hull_prior_min_age_frames, 0);
    MBSLAM_CHECK_OPTION(object_hull_prior_shrink > 0.0 && object_hull_prior_shrink <= 1.0);
    MBSLAM_CHECK_OPTION(long_baseline_frames >= 0 && long_baseline_frames <= 120);
    MBSLAM_CHECK_OPTION_GE(long_baseline_step, 1);
    MBSLAM_CHECK_OPTION_GE(long_baseline_min_ratio, 1.0);
    MBSLAM_CHECK_OPTION(long_baseline_weight > 0.0 && long_baseline_weight <= 1.0);
    MBSLAM_CHECK_OPTION(long_baseline_max_fail_share >= 0.0 && long_baseline_max_fail_share <= 1.0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("likelihood", &likelihood, "epipolar + Flow Vector Bound likelihood");
    v("two_view", &two_view, "robust two-view motion estimate");
    v("pair_ground", &pair_ground, "ground plane of each image pair: depth bound of the rays that meet it");
    v("object_model_max_iterations", &object_model_max_iterations,
      "RANSAC iterations of each moving object's model per image (count)");
    v("multibody", &multibody, "multi-view multibody initialisation (subspace clustering)");
    v("multibody_init", &multibody_init, "(re)initialise bodies by clustering the track window");
    v("multibody_min_frames", &multibody_min_frames, "window for the first initialisation (frames)");
    v("multibody_max_frames", &multibody_max_frames, "longest clustering window (frames)");
    v("multibody_every_frames", &multibody_every_frames, "re-initialisation period, 0 = once (frames)");
    v("multibody_max_tracks", &multibody_max_tracks, "tracks clustered, the rest join by residual (count)");
    v("multibody_min_tracks", &multibody_min_tracks, "complete tracks needed (count)");
    v("multibody_evidence", &multibody_evidence, "log-odds a multibody grouping adds for / against static");
    v("multibody_keep_objects", &multibody_keep_objects, "moving tracks keep the object of the last multibody grouping");
    v("multibody_hold", &multibody_hold, "grouped tracks report the body of the last multibody grouping until the next");
    v("lag_frames", &lag_frames, "reference image this many images back (frames)");
    v("history_frames", &history_frames, "per-track history; longest reference lag (frames)");
    v("target_parallax_px", &target_parallax_px, "reference goes back until static tracks moved this much (px)");
    v("evidence_weight", &evidence_weight, "exponent on each image's likelihood ratio");
    v("likelihood_tail", &likelihood_tail, "added to both hypotheses' likelihoods (robustness)");
    v("min_static_evidence", &min_static_evidence, "weight kept by static evidence of low-parallax pairs");
    v("p_clamp", &p_clamp, "posterior clamp");
    v("static_enter", &static_enter, "P(static) to become static");
    v("static_leave", &static_leave, "P(static) below which a track is moving");
    v("neighbour_prior_radius", &neighbour_prior_radius, "prior radius for new tracks (fraction of width)");
    v("object_hull_prior", &object_hull_prior,
      "new tracks inside a confirmed moving object's hull take its members' prior and join it");
    v("object_hull_prior_shrink", &object_hull_prior_shrink,
      "... the hull scaled about its members' centroid by this (fraction)");
    v("object_hull_prior_min_age_frames", &object_hull_prior_min_age_frames,
      "... only objects segmented for at least this many images (frames)");
    v("min_object_tracks", &min_object_tracks, "tracks needed for an object (count)");
    v("confirm_frames", &confirm_frames, "frames a cluster must persist (frames)");
    v("object_timeout_frames", &object_timeout_frames, "unseen objects removed after (frames)");
    v("cluster_radius", &cluster_radius, "clustering proximity (fraction of image width)");
    v("coherence_abs_px", &coherence_abs_px, "coherent flow difference (px over the lag)");
    v("coherence_rel", &coherence_rel, "coherent flow difference relative to the flow");
    v("distance_std_px", &distance_std_px, "allowed std of pair distances (px)");
    v("distance_std_rel", &distance_std_rel, "allowed std of pair distances (fraction)");
    v("min_model_tracks", &min_model_tracks, "tracks for an object's own motion model (count)");
    v("world_min_tracks", &world_min_tracks, "static tracks to estimate the world motion (count)");
    v("world_min_p_static", &world_min_p_static, "P(static) for taking part in the world-motion RANSAC");
    v("world_check_trigger", &world_check_trigger,
      "share of static tracks a map's world motion leaves unexplained that triggers its check against a two-view estimate [0, 1] (0 = never)");
    v("world_check_min_ratio", &world_check_min_ratio,
      "a map's world motion is replaced when it explains fewer static tracks than this share of the two-view estimate's (0, 1]");
    v("translation_lag_tries", &translation_lag_tries,
      "a pure-rotation reference motion: references 2x, 4x ... as far back tried this often for a measurable translation (count)");
    v("young_heading_from_reference", &young_heading_from_reference,
      "a pure-rotation image-to-image motion takes the reference motion's translation direction for the young tracks");
    v("long_baseline_frames", &long_baseline_frames,
      "static tracks also judged by the flow bound against an image this far back, with SLAM / odometry motion (frames; 0 = off)");
    v("long_baseline_step", &long_baseline_step, "... references tried every this many images (frames)");
    v("long_baseline_min_ratio", &long_baseline_min_ratio, "... only this many times farther back than the image's reference (ratio)");
    v("long_baseline_weight", &long_baseline_weight, "... exponent on the long pair's likelihood ratio");
    v("long_baseline_max_fail_share", &long_baseline_max_fail_share,
      "... a pair whose bound fails for more of its static tracks is not used (fraction)");
  }
};

// One track observed in the current image.
struct TrackObservation {
  int64_t id = 0;
  Eigen::Vector2d uv = Eigen::Vector2d::Zero();  // distorted pixel position
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();  // normalised undistorted coordinates
};

struct SegmenterInput {
  int64_t frame_index = 0;
  int width = 0;          // image width (px)
  int height = 0;         // image height (px)
  double focal_px = 1.0;  // mean focal length (px)
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  // intrinsics (for the epipole in px)
  std::vector<TrackObservation> observations;
  // Motion of the camera w.r.t. the static world between two frame indices (SLAM or
  // odometry); nullopt = estimate it from the tracks.
  std::function<std::optional<RelativeMotion>(int64_t ref_frame, int64_t cur_frame)> world_motion;
  // Depth bounds of a track in the reference camera (map); nullptr = [0, inf).
  std::function<DepthBound(int64_t track_id, const Eigen::Vector2d& xy_ref, int64_t ref_frame)> depth_bound;
};

struct TrackLabel {
  int64_t id = 0;
  int body_id = -1;          // 0 static world, > 0 object, -1 unassigned (moving, no object yet / outlier)
  double p_static = 0.5;     // posterior P(static w.r.t. the world)
  double epipolar_px = NAN;  // last distance to the world's mean epipolar line (px)
  double p_fvb = NAN;        // last P_FVB
  bool evaluated = false;    // has a likelihood from this image
};

struct SegmentedObject {
  int id = 0;
  int64_t first_frame = 0;
  int64_t last_frame = 0;
  std::vector<int64_t> track_ids;           // members observed in this image
  std::vector<Eigen::Vector2d> hull;        // convex hull (px)
  Eigen::Vector2d mean_flow_px = Eigen::Vector2d::Zero();  // mean flow per image (px)
  bool has_motion_model = false;
};

struct SegmentationResult {
  int64_t frame_index = 0;
  std::vector<TrackLabel> labels;   // one per observation, same order
  std::vector<SegmentedObject> objects;
  std::optional<RelativeMotion> world_motion;  // used for this image (ref -> current)
  int64_t world_ref_frame = -1;
  int pair_ground_inliers = 0;       // tracks on the pair's ground plane (0: none found / used)
  int long_baseline_tracks = 0;      // tracks judged by the long-baseline flow bound
  bool world_motion_replaced = false; // the caller's world motion disagreed with the image: the two-view estimate was used
  Eigen::Vector3d epipole = Eigen::Vector3d::Zero();  // homogeneous, px
  bool initialized = false;          // the static world has been identified
};

class MotionSegmenter {
 public:
  explicit MotionSegmenter(const SegmentationOptions& options);

  SegmentationResult Update(const SegmenterInput& input);
  void Reset();

  // Labels by id after the last Update (for feeding back to the tracker).
  const std::unordered_map<int64_t, int>& body_of_track() const { return body_of_track_; }

 private:
  struct TrackState {
    int64_t id = 0;
    std::vector<int64_t> frames;          // observation frames, oldest first
    std::vector<Eigen::Vector2d> xy;      // normalised
    std::vector<Eigen::Vector2d> uv;      // px
    double p_static = 0.5;
    bool moving = false;                  // hysteresis state
    int object = 0;                       // > 0: member of that object (or candidate)
    int multibody_object = -1;            // object of the last multibody grouping (0 world, -1 none)
    int64_t last_frame = 0;
    double epipolar_px = NAN;
    double p_fvb = NAN;
    std::map<int, double> p_object;       // P(static w.r.t. object) for objects with a model

    bool At(int64_t frame, Eigen::Vector2d* xy_out, Eigen::Vector2d* uv_out = nullptr) const;
  };
  struct ObjectState {
    int id = 0;
    int64_t first_frame = 0;
    int64_t last_frame = 0;
    int confirmations = 0;
    bool confirmed = false;
    std::optional<RelativeMotion> motion;
  };

  void UpdateHistories(const SegmenterInput& input);
  // `use_heading`: the two-view estimate tries the last image's translation direction.
  // The world motion from `ref` to this image: the caller's (a map's checked against the
  // tracks believed static, world_check_*, when `replaced` is given; it says when the
  // image disagreed), else the two-view estimate.
  std::optional<RelativeMotion> WorldMotion(const SegmenterInput& input, int64_t ref, bool use_heading = false,
                                            bool* replaced = nullptr);
  // Returns the tracks on the pair's ground plane (0 if none was found or used).
  int UpdateStaticProbabilities(const SegmenterInput& input, int64_t ref, const RelativeMotion& motion);
  // The long-baseline flow bound (options long_baseline_*); returns the tracks judged.
  int UpdateLongBaseline(const SegmenterInput& input, int64_t ref);
  void UpdateObjectModels(const SegmenterInput& input, int64_t ref);
  // Observations kept per track for the usual reference search and clustering (the
  // long baseline may keep more).
  int BaseHistory() const;
  void ClusterUnexplained(const SegmenterInput& input, int64_t ref);
  // `parallax_px`: how much the pair could tell; static evidence from pairs with little
  // parallax is discounted (they cannot reveal a degenerate mover yet).
  double BayesUpdate(double prior, double likelihood, double parallax_px) const;
  // Sec. 3.4: segments the tracks complete over the recent window into motions, picks
  // the static world and (re)labels tracks and objects. Returns false if it did not run.
  bool MultibodyInitialize(const SegmenterInput& input);
  int64_t ChooseReference(const SegmenterInput& input) const;
  // The oldest image a reference can be: the oldest kept by any current track, at most
  // history_frames back.
  int64_t EarliestReference(const SegmenterInput& input) const;

  const SegmentationOptions options_;
  std::unordered_map<int64_t, TrackState> tracks_;
  std::map<int, ObjectState> objects_;
  std::unordered_map<int64_t, int> body_of_track_;
  int next_object_id_ = 1;
  int64_t frame_ = -1;
  int64_t first_frame_ = -1;
  int64_t last_multibody_frame_ = -1;
  std::optional<Eigen::Vector3d> last_heading_;  // translation direction of the last world motion (current camera)
  bool initialized_ = false;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_SEGMENTATION_MOTION_SEGMENTER_H_
