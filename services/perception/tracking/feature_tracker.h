#ifndef MBSLAM_SERVICES_PERCEPTION_TRACKING_FEATURE_TRACKER_H_
#define MBSLAM_SERVICES_PERCEPTION_TRACKING_FEATURE_TRACKER_H_

// Feature tracking of thesis chapter 2: FAST corners spread over the image by a grid,
// new features every frame, pyramidal KLT with forward-backward and unicity checks,
// two-stage matching (wide search first so that movers survive, then guided matching
// of lost / occluded tracks around positions predicted by the bodies' motion),
// occlusion by moving objects' hulls (occluded tracks are kept, not matched, until
// they reappear), and affine patch warps when the pose is known (tracks re-aligned on
// their reference appearance warped into the new view, against KLT's drift).

#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include "common/config/options.h"
#include "services/perception/geometry/polygon.h"
#include "services/perception/tracking/disc_stamp.h"
#include "services/perception/tracking/klt.h"
#include "services/perception/tracking/track.h"

namespace mbslam {

struct TrackerOptions {
  int max_features = 1000;             // tracks kept per image (count)
  int grid_cols = 16;                  // detection grid columns (count)
  int grid_rows = 12;                  // detection grid rows (count)
  int fast_threshold = 15;             // FAST intensity threshold (gray levels)
  int min_fast_threshold = 5;          // retried in cells that find nothing (gray levels)
  double min_distance_px = 8.0;        // minimum spacing of features (px)
  int border_px = 8;                   // features closer to the border are dropped (px)
  int klt_window_px = 15;              // KLT window side (px)
  int klt_levels = 3;                  // pyramid levels used by KLT (count)
  int klt_backward_levels = 3;         // levels of the backward (consistency) pass; fewer are faster but let more false matches through (count)
  // Fast image motion (low frame rate, quick turns): when the tracks moved more than
  // klt_fast_flow_px (median) in the previous image, KLT uses a wider window and more
  // levels for this one (0 = off).
  double klt_fast_flow_px = 10.0;      // median track motion that switches to the fast settings (px)
  int klt_fast_window_px = 21;         // KLT window under fast motion (px)
  int klt_fast_levels = 4;             // KLT pyramid levels under fast motion (count; <= preprocess.pyramid_levels)
  int klt_max_iterations = 12;         // KLT iterations per level (count)
  int klt_threads = 2;                 // KLT points split over this many threads (identical result; count)
  double klt_epsilon = 0.05;           // KLT convergence (px)
  // "mbslam": the project's KLT (klt.h, about a fifth of the instructions of OpenCV's); "opencv":
  // cv::calcOpticalFlowPyrLK. Same algorithm; the results differ in the last bits.
  std::string klt_backend = "mbslam";
  double klt_min_eigen = 0.1;          // mbslam KLT: untrackable window below this smaller eigenvalue per pixel ((gray / px)^2)
  double max_forward_backward_px = 0.8;  // forward-backward consistency (px)
  double unicity_px = 1.2;             // two tracks closer than this keep only the better (px)
  int max_occluded_frames = 45;        // an occluded track is dropped after this (frames)
  int patch_size = 11;                 // ZSSD template side for guided matching (px)
  int guided_radius_px = 8;            // guided search half-window (px)
  double max_patch_score = 400.0;      // accept a guided match below this ZSSD / pixel (gray^2)
  double velocity_smoothing = 0.5;     // weight of the newest flow in the velocity estimate
  double min_patch_ncc = 0.6;          // appearance check of every KLT match against the track's template (NCC)
  double min_anchor_ncc = 0.4;         // ... and against its first appearance: catches tracks dragged along occlusion boundaries (NCC)
  // Affine patch warps when the pose is known (thesis sec. 2.2): frame-to-frame KLT
  // drifts under strong perspective change (ground tracks near the camera: 5-20 px over
  // 40-70 images in sim-following). Tracks of known 3D position are re-aligned on their
  // reference appearance warped into the current view (SetWarpReferences /
  // AlignToReferences; the caller supplies the warps).
  bool warp_align = true;              // the perception loop re-aligns static map tracks on warped references
  int warp_align_every = 1;            // each track is re-aligned every this many images (staggered by id)
  int warp_reference_px = 31;          // side of the stored reference patch, odd (px)
  double warp_align_max_px = 0.5;      // larger corrections are not taken: tracks are re-aligned every image, so a correction absorbs one image's drift (px)
  double warp_align_min_ncc = 0.8;     // the warped reference must match this well after alignment (NCC)
  double warp_max_scale = 2.0;         // warps that scale a patch by more than this (either way) are not used
  double warp_rereference_scale = 1.4; // ... by more than this: the track takes a new reference at the next keyframe
  double warp_ground_band = 0.1;       // points this close to the ground plane (share of the camera's height) take its normal
  bool descriptor_fallback = true;     // when KLT keeps too few tracks (low frame rate, wide baseline), match ORB descriptors
  double fallback_survival = 0.5;      // KLT survival share below which the fallback runs
  int fallback_features = 1500;        // ORB features detected for the fallback (count)
  int fallback_max_hamming = 50;       // descriptor acceptance (bits)
  double fallback_ratio = 0.8;         // Lowe ratio test
  double fallback_radius = 0.35;       // search radius (fraction of the image diagonal)
  // The lost tracks' descriptors take ORB's orientation (intensity centroid), as the new
  // image's keypoints do: unoriented they match only where the view has not turned (a
  // 25 deg turn: 12 re-found against 140). Off by default: on TartanAir the re-found
  // tracks (ORB keypoint positions) make the ATE worse, mean over five starts 1.09 ->
  // 1.88 % of the path; TUM cabinet still does not initialise. Both sides follow it in
  // the wide-baseline fallback (below).
  bool fallback_orientation = false;
  // Images this far apart or more (a low frame rate) are a wide baseline: the fallback
  // then describes both sides alike, on one pyramid level (the lost tracks' descriptors
  // are single-level; against ORB's 8 levels they matched 8 of hundreds on TUM cabinet,
  // 1.5 Hz), with the orientation as fallback_orientation says on both sides, and detects
  // with a lower FAST threshold (wide_baseline_fast_threshold); and an image that loses
  // most tracks is not taken for a glitch (glitch_max_survival). At video rates the usual
  // fallback stays: the consistent one made TartanAir (10 Hz) worse (0.83 -> 1.16 % ATE).
  int64_t wide_baseline_min_interval_us = 200000;  // 0 = never
  int wide_baseline_fast_threshold = 7;            // FAST threshold of the wide-baseline fallback (gray levels)
  // A glitch image (a flash, a corrupted or foreign frame) loses nearly every established
  // track at once: the image is rejected, the tracks are kept and the next image is
  // tracked from the last good one. Not twice in a row (a real change of view is taken).
  double glitch_max_survival = 0.2;    // established tracks matched below this share: glitch (0 = off)
  int glitch_min_tracks = 40;          // ... only with at least this many established tracks (count)
  // An exposure step (automatic exposure, a rendered sequence's): KLT assumes constant
  // brightness, and under a step it matches few tracks (the image looks like a glitch)
  // or matches them off target. The change is measured on the matched tracks' patches
  // against their templates (medians of the contrast ratios and mean differences; on
  // the whole images when too few matched); when the mean moves or the contrast changes
  // by more than these, the image is mapped linearly onto the previous exposure and
  // tracked again, and the attempt that keeps more established tracks stands. Later
  // images are tracked from the corrected one.
  bool exposure_compensation = true;
  double exposure_min_mean_change = 5.0;      // mean grey level change that triggers it (grey levels)
  double exposure_min_contrast_change = 0.05; // ... or relative change of the standard deviation (fraction)
  // Denser features on moving objects (TrackingHints::occluders, the moving hulls): a
  // small object gets as many tracks as a grid cell allows the background, too few for
  // its motion model and its own reconstruction. Inside each hull, new features are
  // added more closely spaced until it holds object_features tracks, above
  // max_features by at most object_extra_features in all.
  int object_features = 0;             // tracks wanted inside each moving hull (count; 0 = off)
  int object_extra_features = 200;     // tracks these may add above max_features in all (count)
  double object_min_distance_px = 4.0; // spacing of the features added there (px)
  double object_hull_margin_px = 3.0;  // ... at least this far inside the hull, off its boundary (px)
  double object_max_hull_share = 0.05; // ... only in hulls smaller than this share of the image (fraction)
  int object_min_age_frames = 0;       // ... only of objects segmented for at least this many images (frames)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(max_features, 0);
    MBSLAM_CHECK_OPTION_GT(grid_cols, 0);
    MBSLAM_CHECK_OPTION_GT(grid_rows, 0);
    MBSLAM_CHECK_OPTION_GT(fast_threshold, 0);
    MBSLAM_CHECK_OPTION_GT(min_fast_threshold, 0);
    MBSLAM_CHECK_OPTION_GE(min_distance_px, 1.0);
    MBSLAM_CHECK_OPTION_GE(border_px, 0);
    MBSLAM_CHECK_OPTION_GE(klt_window_px, 5);
    MBSLAM_CHECK_OPTION_GE(klt_levels, 1);
    MBSLAM_CHECK_OPTION(klt_backward_levels >= 1 && klt_backward_levels <= klt_levels);
    MBSLAM_CHECK_OPTION_GE(klt_fast_flow_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(klt_fast_window_px, klt_window_px);
    MBSLAM_CHECK_OPTION_GE(klt_fast_levels, klt_levels);
    MBSLAM_CHECK_OPTION_GT(klt_max_iterations, 0);
    MBSLAM_CHECK_OPTION(klt_threads >= 1 && klt_threads <= 16);
    MBSLAM_CHECK_OPTION_GT(klt_epsilon, 0.0);
    MBSLAM_CHECK_OPTION(klt_backend == "mbslam" || klt_backend == "opencv");
    MBSLAM_CHECK_OPTION_GE(klt_min_eigen, 0.0);
    MBSLAM_CHECK_OPTION(klt_window_px % 2 == 1 && klt_fast_window_px % 2 == 1 && klt_fast_window_px <= 63);
    MBSLAM_CHECK_OPTION_GT(max_forward_backward_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(unicity_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_occluded_frames, 0);
    MBSLAM_CHECK_OPTION_GE(patch_size, 5);
    MBSLAM_CHECK_OPTION(patch_size % 2 == 1);
    MBSLAM_CHECK_OPTION_GE(guided_radius_px, 1);
    MBSLAM_CHECK_OPTION_GT(max_patch_score, 0.0);
    MBSLAM_CHECK_OPTION(velocity_smoothing > 0.0 && velocity_smoothing <= 1.0);
    MBSLAM_CHECK_OPTION(min_patch_ncc >= -1.0 && min_patch_ncc < 1.0);
    MBSLAM_CHECK_OPTION(min_anchor_ncc >= -1.0 && min_anchor_ncc < 1.0);
    MBSLAM_CHECK_OPTION_GE(warp_align_every, 1);
    MBSLAM_CHECK_OPTION(warp_reference_px >= patch_size + 2 && warp_reference_px % 2 == 1);
    MBSLAM_CHECK_OPTION_GT(warp_align_max_px, 0.0);
    MBSLAM_CHECK_OPTION(warp_align_min_ncc >= -1.0 && warp_align_min_ncc < 1.0);
    MBSLAM_CHECK_OPTION_GE(warp_max_scale, 1.0);
    MBSLAM_CHECK_OPTION(warp_rereference_scale >= 1.0 && warp_rereference_scale <= warp_max_scale);
    MBSLAM_CHECK_OPTION_GE(warp_ground_band, 0.0);
    MBSLAM_CHECK_OPTION(fallback_survival >= 0.0 && fallback_survival <= 1.0);
    MBSLAM_CHECK_OPTION_GE(wide_baseline_min_interval_us, 0);
    MBSLAM_CHECK_OPTION(wide_baseline_fast_threshold >= 1 && wide_baseline_fast_threshold <= 255);
    MBSLAM_CHECK_OPTION_GT(fallback_features, 0);
    MBSLAM_CHECK_OPTION(fallback_max_hamming > 0 && fallback_max_hamming <= 256);
    MBSLAM_CHECK_OPTION(fallback_ratio > 0.0 && fallback_ratio <= 1.0);
    MBSLAM_CHECK_OPTION(fallback_radius > 0.0 && std::isfinite(fallback_radius));
    MBSLAM_CHECK_OPTION(glitch_max_survival >= 0.0 && glitch_max_survival < 1.0);
    MBSLAM_CHECK_OPTION_GE(glitch_min_tracks, 1);
    MBSLAM_CHECK_OPTION_GE(exposure_min_mean_change, 0.0);
    MBSLAM_CHECK_OPTION_GE(exposure_min_contrast_change, 0.0);
    MBSLAM_CHECK_OPTION_GE(object_features, 0);
    MBSLAM_CHECK_OPTION_GE(object_extra_features, 0);
    MBSLAM_CHECK_OPTION_GE(object_min_distance_px, 1.0);
    MBSLAM_CHECK_OPTION_GE(object_hull_margin_px, 0.0);
    MBSLAM_CHECK_OPTION(object_max_hull_share > 0.0 && object_max_hull_share <= 1.0);
    MBSLAM_CHECK_OPTION_GE(object_min_age_frames, 0);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("max_features", &max_features, "tracks kept per image (count)");
    v("grid_cols", &grid_cols, "detection grid columns (count)");
    v("grid_rows", &grid_rows, "detection grid rows (count)");
    v("fast_threshold", &fast_threshold, "FAST threshold (gray levels)");
    v("min_fast_threshold", &min_fast_threshold, "FAST threshold retried in empty cells (gray levels)");
    v("min_distance_px", &min_distance_px, "minimum feature spacing (px)");
    v("border_px", &border_px, "image border without features (px)");
    v("klt_window_px", &klt_window_px, "KLT window side (px)");
    v("klt_levels", &klt_levels, "KLT pyramid levels (count)");
    v("klt_threads", &klt_threads, "KLT points split over this many threads, identical result (count)");
    v("klt_backward_levels", &klt_backward_levels, "levels of the backward consistency pass, which starts at the answer (count)");
    v("klt_fast_flow_px", &klt_fast_flow_px, "median track motion above which KLT uses the fast settings (px; 0 = off)");
    v("klt_fast_window_px", &klt_fast_window_px, "KLT window under fast motion (px)");
    v("klt_fast_levels", &klt_fast_levels, "KLT pyramid levels under fast motion (count)");
    v("klt_max_iterations", &klt_max_iterations, "KLT iterations per level (count)");
    v("klt_epsilon", &klt_epsilon, "KLT convergence (px)");
    v("klt_backend", &klt_backend, "mbslam (the project's KLT, faster) or opencv (cv::calcOpticalFlowPyrLK)");
    v("klt_min_eigen", &klt_min_eigen, "mbslam KLT: smaller eigenvalue per pixel below which a window is untrackable ((gray/px)^2)");
    v("max_forward_backward_px", &max_forward_backward_px, "forward-backward check (px)");
    v("unicity_px", &unicity_px, "tracks closer than this keep only the better one (px)");
    v("max_occluded_frames", &max_occluded_frames, "occluded tracks dropped after (frames)");
    v("patch_size", &patch_size, "ZSSD template side, odd (px)");
    v("guided_radius_px", &guided_radius_px, "guided search half-window (px)");
    v("max_patch_score", &max_patch_score, "guided match acceptance, ZSSD per pixel (gray^2)");
    v("velocity_smoothing", &velocity_smoothing, "weight of the newest flow in track velocity (0..1]");
    v("min_patch_ncc", &min_patch_ncc, "appearance check of KLT matches against the template (NCC)");
    v("min_anchor_ncc", &min_anchor_ncc, "appearance check against the first observation (NCC)");
    v("warp_align", &warp_align, "static map tracks re-aligned on their keyframe appearance warped by the known pose");
    v("warp_align_every", &warp_align_every, "each track re-aligned every this many images, staggered by id (count)");
    v("warp_reference_px", &warp_reference_px, "side of the reference patch for affine warps, odd (px)");
    v("warp_align_max_px", &warp_align_max_px, "largest correction by alignment on the warped reference (px)");
    v("warp_align_min_ncc", &warp_align_min_ncc, "the warped reference must match this well after alignment (NCC)");
    v("warp_max_scale", &warp_max_scale, "warps scaling a patch by more than this either way are not used");
    v("warp_rereference_scale", &warp_rereference_scale,
      "warps scaling by more than this: new reference at the next keyframe");
    v("warp_ground_band", &warp_ground_band,
      "points this close to the ground plane (share of the camera height) take its normal for the warp");
    v("descriptor_fallback", &descriptor_fallback, "ORB matching when KLT keeps too few tracks");
    v("fallback_survival", &fallback_survival, "KLT survival share that triggers the fallback");
    v("fallback_features", &fallback_features, "ORB features for the fallback (count)");
    v("fallback_max_hamming", &fallback_max_hamming, "ORB acceptance distance (bits)");
    v("fallback_ratio", &fallback_ratio, "Lowe ratio test of the fallback");
    v("fallback_radius", &fallback_radius, "fallback search radius (fraction of the diagonal)");
    v("fallback_orientation", &fallback_orientation,
      "the lost tracks' ORB descriptors are oriented (intensity centroid), as the new image's keypoints are");
    v("wide_baseline_min_interval_us", &wide_baseline_min_interval_us,
      "images this far apart are a wide baseline: the fallback describes both sides alike on one level (us, 0 = never)");
    v("wide_baseline_fast_threshold", &wide_baseline_fast_threshold,
      "FAST threshold of the wide-baseline fallback (gray levels)");
    v("glitch_max_survival", &glitch_max_survival,
      "established tracks matched below this share: the image is a glitch, rejected, tracks kept (0 = off)");
    v("glitch_min_tracks", &glitch_min_tracks, "glitch test only with this many established tracks (count)");
    v("exposure_compensation", &exposure_compensation,
      "an exposure step (measured on the matched patches) is undone and the image tracked again");
    v("exposure_min_mean_change", &exposure_min_mean_change, "mean change that triggers the compensation (grey levels)");
    v("exposure_min_contrast_change", &exposure_min_contrast_change,
      "relative contrast change that triggers the compensation (fraction)");
    v("object_features", &object_features,
      "tracks wanted inside each moving object's hull: new ones added there more densely (count; 0 = off)");
    v("object_extra_features", &object_extra_features, "tracks those may add above max_features in all (count)");
    v("object_min_distance_px", &object_min_distance_px, "spacing of the features added inside moving hulls (px)");
    v("object_hull_margin_px", &object_hull_margin_px, "... at least this far inside the hull (px)");
    v("object_max_hull_share", &object_max_hull_share, "... only in hulls smaller than this share of the image (fraction)");
    v("object_min_age_frames", &object_min_age_frames, "... only of objects segmented for at least this many images (frames)");
  }
};

// Feedback from the other modules for one image.
struct TrackingHints {
  // Predicted position of a track in the new image (from its body's motion), used as
  // the KLT starting point and for guided matching.
  std::unordered_map<int64_t, Eigen::Vector2f> predicted_uv;
  // Convex hulls (px) of moving objects predicted for the new image, with their body.
  struct Hull {
    int body_id = 0;
    std::vector<Eigen::Vector2f> points;
    int age_frames = 0;  // images since the object was first segmented
  };
  std::vector<Hull> occluders;
  int64_t interval_us = 0;  // time since the previous image (0 = unknown)
};

// A track's reference appearance warped into the latest image: `cur_from_ref` maps
// pixel offsets around the track in its reference view to offsets in the latest image.
struct WarpedReference {
  int64_t track_id = 0;
  Eigen::Matrix2f cur_from_ref = Eigen::Matrix2f::Identity();
};

struct WarpAlignStats {
  int tried = 0;       // tracks with a usable reference and warp
  int corrected = 0;   // moved by the alignment
  int refused = 0;     // alignment failed, moved too far or matched badly: left as KLT had it
  double mean_correction_px = 0.0;  // over the corrected ones (px)
};

struct TrackerStats {
  int tracked = 0;        // matched by KLT
  int lost = 0;           // failed KLT / checks
  // Why KLT matches were refused (each refused match counts once, at its first failed check).
  int lost_forward = 0;   // the forward pass did not converge (or left the image)
  int lost_backward = 0;  // the backward pass did not converge
  int lost_consistency = 0;  // forward-backward disagreement above max_forward_backward_px
  int lost_border = 0;    // the match fell within the border
  int lost_appearance = 0;  // the patch did not match the template or the anchor (NCC)
  int occluded = 0;       // kept behind hulls
  int recovered = 0;      // re-found by guided matching
  int created = 0;        // new features
  int created_on_objects = 0;  // of which added inside moving hulls (object_features)
  int rejected_unicity = 0;
  int descriptor_matched = 0;  // recovered by the ORB fallback
  bool fast_motion = false;    // KLT ran with the fast-motion settings
  double median_flow_px = 0.0; // median motion of the tracks matched in this image (px)
  bool rejected = false;       // the image was a glitch (see glitch_max_survival): nothing changed
  bool exposure_corrected = false;  // tracked after undoing an exposure change (exposure_compensation)
  double exposure_gain = 1.0, exposure_offset = 0.0;  // the correction: corrected = gain * image + offset
  int established = 0;         // tracks of age >= 3 tried in this image
  int established_matched = 0;
};

class FeatureTracker {
 public:
  explicit FeatureTracker(const TrackerOptions& options);

  // Tracks into the new image (pyramid level 0 = full resolution), then detects new
  // features in empty grid cells. The tracker keeps `pyramid` (shallow cv::Mat copies)
  // as the previous image: the caller must not write into its buffers afterwards.
  void TrackFrame(const std::vector<cv::Mat>& pyramid, int64_t frame_index, const TrackingHints& hints);

  // Stage 2: re-finds tracks that are occluded or were lost in this image near the
  // given predicted positions (ZSSD on the stored template). Returns the number found.
  int GuidedMatch(const std::unordered_map<int64_t, Eigen::Vector2f>& predicted_uv);

  // Starts a track at a position found by other means (guided matching of a map point)
  // in the latest image; returns its id, or -1 if it is too close to an existing track
  // or to the border.
  int64_t AdoptTrack(const Eigen::Vector2f& uv, int body_id);

  // Stores the reference appearance for affine warps of the given tracks (track id,
  // caller's key) at their positions in the latest image. Tracks not observed in the
  // latest image are skipped. Returns the number stored.
  int SetWarpReferences(const std::vector<std::pair<int64_t, int64_t>>& track_keys);

  // Re-aligns tracks observed in the latest image on their reference appearance warped
  // into it: the KLT position moves to the aligned one when the correction is at most
  // warp_align_max_px and the warped reference matches (warp_align_min_ncc). Warps
  // scaling by more than warp_max_scale are skipped (the caller should re-reference).
  WarpAlignStats AlignToReferences(const std::vector<WarpedReference>& warps);

  std::vector<Track>& tracks() { return tracks_; }
  const std::vector<Track>& tracks() const { return tracks_; }
  const TrackerStats& stats() const { return stats_; }
  const TrackerOptions& options() const { return options_; }

  // Drops every track (tracking reset).
  void Reset();

 private:
  void DetectNew(const cv::Mat& image, int64_t frame_index);
  // Adds features inside the moving hulls (object_features); returns how many.
  int DetectOnObjects(const cv::Mat& image, int64_t frame_index, const std::vector<TrackingHints::Hull>& hulls);
  void EnforceUnicity();
  std::unordered_map<int64_t, size_t> IndexById() const;  // track id -> index in tracks_
  // Fallback: lost tracks re-matched by ORB descriptors. `wide_baseline`: both sides
  // described alike (TrackerOptions::wide_baseline_min_interval_us).
  void MatchByDescriptors(const cv::Mat& prev_image, const cv::Mat& image, int64_t frame_index, bool wide_baseline,
                          std::vector<Track>* lost, std::vector<Track>* next_tracks);

  const TrackerOptions options_;
  std::vector<cv::Mat> prev_pyramid_;
  KltPyramid prev_klt_pyramid_;  // prev_pyramid_ as the project's KLT reads it (klt.h)
  std::vector<Track> tracks_;
  // Tracks lost in the latest image that guided matching may still recover.
  std::vector<Track> recently_lost_;
  int64_t next_id_ = 1;
  DiscStamp disc_{0};  // min-distance discs of DetectNew
  int64_t frame_index_ = -1;
  TrackerStats stats_;
  bool last_rejected_ = false;  // the previous image was rejected as a glitch
  double last_median_flow_px_ = 0.0;  // of the previous image's matched tracks
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_TRACKING_FEATURE_TRACKER_H_
