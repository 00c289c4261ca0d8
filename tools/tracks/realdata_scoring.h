#ifndef MBSLAM_TOOLS_TRACKS_REALDATA_SCORING_H_
#define MBSLAM_TOOLS_TRACKS_REALDATA_SCORING_H_

// Scoring a perception run's moving-feature labels on real image sequences whose ground
// truth is a mask (DAVIS 2016: binary mask of the primary moving object) or a semantic
// label image (CamVid: 11 classes), as ../shared/data/README.md defines it.
//
// Input is the run's output log: PERCEPTION_TRACKS (tracks_t: features with body labels,
// moving hulls) and PERCEPTION_OBJECTS (objects_t: per-object image hulls), matched to
// the ground-truth frames by frame_seq (the camera_driver's image_t.seq, = the index of
// the file in the folder's natural order).
//
// Which features are scored and what counts as "labelled moving" is defined once here
// (ScoredTrack, LabelledMoving): measured tracks only (not FLAG_NEW, not FLAG_OCCLUDED,
// the same filter as mbslam-eval-segmentation), labelled moving when assigned to a moving
// object (body_id > 0). Unassigned / outlier tracks (body_id = -1) are not labelled
// moving; they are counted apart.

#include <opencv2/core.hpp>

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/lcm/channels.h"
#include "common/util/status.h"
#include "mbslam/feature_track_t.hpp"
#include "tools/eval/datasets.h"
#include "tools/eval/segmentation_metrics.h"

namespace mbslam {
namespace eval {

// ---------------------------------------------------------------- run output per image

// A polygon in image coordinates (px) with the body it belongs to.
struct ImagePolygon {
  int body_id = 0;
  std::vector<cv::Point2f> points;
};

struct PerceptionFrame {
  int64_t frame_seq = -1;
  int64_t utime = 0;
  int width = 0;   // px (tracks_t)
  int height = 0;  // px
  bool has_tracks = false;   // a tracks_t message was read for this image
  bool has_objects = false;  // an objects_t message was read for this image
  std::vector<LabelledFeature> features;  // scored features (ScoredTrack) with LabelledMoving
  std::vector<int> body_ids;              // body_id of each entry of `features`
  std::vector<mbslam::feature_track_t> tracks;  // the scored tracks themselves (diagnostics)
  int num_unassigned = 0;                 // scored features with body_id < 0 (count)
  int num_skipped = 0;                    // new or occluded features, not scored (count)
  std::vector<ImagePolygon> object_hulls;  // objects_t: hull of each object (>= 3 vertices)
  std::vector<ImagePolygon> track_hulls;   // tracks_t: hull of each visible moving object
};

// The feature filter and label shared by every mask-based scorer.
bool ScoredTrack(const mbslam::feature_track_t& track);
bool LabelledMoving(int body_id);

// Reads PERCEPTION_TRACKS and PERCEPTION_OBJECTS of a run's output log, by frame_seq.
// Undecodable messages are counted in *num_undecodable (if given) and skipped.
Status ReadPerceptionFrames(const std::string& log_path, const ChannelOptions& channels,
                            std::map<int64_t, PerceptionFrame>* frames,
                            int* num_undecodable = nullptr);

// ---------------------------------------------------------------- moving region

enum class RegionSource {
  kNone,           // nothing labelled moving: empty region
  kObjectHulls,    // union of the objects' image hulls (PERCEPTION_OBJECTS)
  kTrackHulls,     // union of the hulls on PERCEPTION_TRACKS (no objects_t for the image)
  kFeatureHulls,   // union of the convex hulls of the moving features grouped by body_id
};
const char* RegionSourceName(RegionSource source);

// Predicted moving region (CV_8U, 255 inside) of one image: the objects' hulls when the
// image has any, else the tracks message's hulls, else the convex hulls of the moving
// features per body (bodies with >= 3 features).
cv::Mat MovingRegion(const PerceptionFrame& frame, cv::Size size, RegionSource* source = nullptr);

// ---------------------------------------------------------------- DAVIS-style mask scoring

// IoU of a mask with the union of the convex hulls of its connected parts: the J a region
// made of one perfect hull per object could reach (context for hull-based J; 1 for convex
// parts and for an empty mask).
double ConvexHullIoU(const cv::Mat& mask);

// One image. Precision is undefined (NaN) when no feature is labelled moving; recall is
// undefined when no scored feature lies inside the mask. IoU (J) is always defined: |R and
// M| / |R or M| with an empty predicted region giving 0 (1 if the mask is empty too).
struct MaskFrameScore {
  int64_t frame_seq = -1;
  bool has_output = false;       // the run published tracks for this image
  PrecisionRecall counts;        // TP / FP / FN / TN features
  double precision = 0.0;        // NaN when undefined
  double recall = 0.0;           // NaN when undefined
  double iou = 0.0;
  RegionSource region_source = RegionSource::kNone;
  int num_features = 0;          // scored features inside the image (count)
  int num_moving = 0;            // of them labelled moving (count)
  int num_unassigned = 0;        // scored features with body_id < 0 (count)
  int fp_near_mask = 0;          // false positives within near_px of the mask (diagnostic, count)
  PrecisionRecall counts_with_unassigned;  // the same counts with unassigned tracks (body_id < 0,
                                           // "moving, no object yet / outlier") taken as moving
};
// Distance (px) under which a false positive counts as "near" the truth (boundary, shadows,
// coarse labels): diagnostic only, the scores above do not use it.
constexpr double kNearTruthPx = 8.0;
// `frame` may be null (the run published nothing for this image: no features, empty region).
MaskFrameScore ScoreMaskFrame(const PerceptionFrame* frame, const cv::Mat& mask);

// Per sequence: means over images of the defined per-image values; pooled (micro) counts.
struct MaskSequenceScore {
  std::string name;
  int frames = 0;                      // ground-truth images scored (count)
  int frames_without_output = 0;       // no tracks_t for the image (count)
  int frames_precision_undefined = 0;  // no feature labelled moving (excluded from mean_precision)
  int frames_recall_undefined = 0;     // no scored feature inside the mask (excluded from mean_recall)
  double mean_precision = 0.0;  // mean over images with precision defined; NaN if none
  double mean_recall = 0.0;     // mean over images with recall defined; NaN if none
  double mean_iou = 0.0;        // mean over all images
  double mean_hull_iou_ceiling = 0.0;  // mean ConvexHullIoU of the truth (ScoreDavisSequence only)
  PrecisionRecall pooled;       // summed counts over the sequence
  PrecisionRecall pooled_with_unassigned;  // ... with unassigned tracks taken as moving
  int unassigned = 0;           // scored features with body_id < 0 (count)
  int fp_near_mask = 0;         // false positives within kNearTruthPx of the mask (count)
  std::map<RegionSource, int> region_sources;  // images per region source
  std::vector<MaskFrameScore> per_frame;
};
MaskSequenceScore SummarizeMaskSequence(const std::string& name,
                                        const std::vector<MaskFrameScore>& frames);

// Scores a run on a DAVIS sequence: every annotated image i is matched to frame_seq i.
Status ScoreDavisSequence(const DavisSequence& sequence,
                          const std::map<int64_t, PerceptionFrame>& run, MaskSequenceScore* score);

// Mean over sequences of the per-sequence means (NaN entries skipped).
struct MaskDatasetScore {
  double mean_precision = 0.0;
  double mean_recall = 0.0;
  double mean_iou = 0.0;
  int sequences = 0;
  PrecisionRecall pooled;
  PrecisionRecall pooled_with_unassigned;
};
MaskDatasetScore SummarizeMaskDataset(const std::vector<MaskSequenceScore>& sequences);

// ---------------------------------------------------------------- CamVid-style class scoring

struct CamVidRunScore {
  int frames = 0;                   // labelled images with tracks from the run (count)
  int frames_without_output = 0;    // labelled images without (count)
  int features = 0;                 // scored features inside the images (count)
  CamVidFeatureStats moving;        // where the moving-labelled features fall
  int on_movable = 0;               // scored features on car / pedestrian / bicyclist (count)
  int on_movable_moving = 0;        // of them labelled moving (count)
  int on_static = 0;                // scored features on static classes (count)
  std::map<int, int> moving_per_class;  // moving-labelled features per class label
  std::map<int, int> per_class;         // scored features per class label
  int unassigned = 0;               // scored features with body_id < 0 (count)
  CamVidFeatureStats non_static;    // where the features not labelled static (body_id != 0) fall
  int moving_on_static_near_movable = 0;  // moving on static classes within kNearTruthPx of a
                                          // car / pedestrian / bicyclist pixel (diagnostic, count)
  // Derived (Finish()):
  double moving_on_static = 0.0;    // moving.on_static / moving.moving (0 if none)
  double moving_on_movable = 0.0;   // moving.on_movable / moving.moving
  double movable_labelled_moving = 0.0;  // on_movable_moving / on_movable (recall proxy)
  double static_labelled_moving = 0.0;   // moving.on_static / on_static (false moving rate)
  double non_static_on_static = 0.0;     // non_static.on_static / non_static.moving
  void AddFrame(const PerceptionFrame& frame, const cv::Mat& labels);
  void Finish();
};

// Scores a run on CamVid-style frames: labelled image i is matched to frame_seq i
// (the driver publishes the images folder in order and it holds the labelled frames only).
Status ScoreCamVid(const std::vector<CamVidFrame>& frames,
                   const std::map<int64_t, PerceptionFrame>& run, CamVidRunScore* score);

// ---------------------------------------------------------------- static scenes

// A sequence whose world does not move (TartanAir, TUM cabinet): every feature labelled
// moving is a false one, and every object a phantom.
struct StaticSceneScore {
  int frames = 0;               // images with tracks from the run (count)
  int features = 0;             // scored features (count)
  int moving = 0;               // of them labelled moving (body_id > 0) (count)
  int unassigned = 0;           // of them with body_id < 0 (count)
  int frames_with_moving = 0;   // images with at least one feature labelled moving (count)
  std::set<int> objects;        // ids of the objects the moving features belong to (phantoms)
  // Derived (Finish()):
  double false_moving = 0.0;              // moving / features (0 without features)
  double frames_with_moving_share = 0.0;  // frames_with_moving / frames
  void AddFrame(const PerceptionFrame& frame);
  void Finish();
};

// Scores every image of a run on a static scene.
StaticSceneScore ScoreStaticScene(const std::map<int64_t, PerceptionFrame>& run);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_TRACKS_REALDATA_SCORING_H_
