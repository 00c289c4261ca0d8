#ifndef MBSLAM_TOOLS_EVAL_SEGMENTATION_METRICS_H_
#define MBSLAM_TOOLS_EVAL_SEGMENTATION_METRICS_H_

// Motion segmentation metrics: track-level misclassification under the best one-to-one
// matching of predicted to true groups (Hungarian), moving-feature precision / recall
// against masks, and region IoU.

#include <opencv2/core.hpp>

#include <map>
#include <vector>

namespace mbslam {
namespace eval {

struct MisclassificationResult {
  int num_points = 0;  // labelled points (count)
  int num_errors = 0;  // points whose predicted group is not matched to their true group
  double rate = 0.0;   // num_errors / num_points
  int num_true_groups = 0;
  int num_pred_groups = 0;
  std::map<int, int> pred_to_true;  // the matching (predicted label -> true label)
};

// Labels are arbitrary integers; a negative predicted label means "unassigned" and is
// always an error. Predicted and true group counts may differ: unmatched groups' points
// are errors.
MisclassificationResult Misclassification(const std::vector<int>& predicted,
                                          const std::vector<int>& truth);

struct PrecisionRecall {
  int true_positives = 0;
  int false_positives = 0;
  int false_negatives = 0;
  int true_negatives = 0;
  double precision = 0.0;  // TP / (TP + FP); 1 when nothing was predicted positive
  double recall = 0.0;     // TP / (TP + FN); 1 when there is nothing to find
  double f1 = 0.0;
  void Add(const PrecisionRecall& other);  // sums the counts and recomputes the ratios
  void Finish();
};

// A feature labelled moving (or not) at pixel (u, v).
struct LabelledFeature {
  double u = 0.0;  // px
  double v = 0.0;  // px
  bool moving = false;
};

// A feature is a true positive if it is labelled moving and the mask is non-zero at its
// pixel. Features outside the mask image are ignored.
PrecisionRecall MovingFeaturePrecisionRecall(const std::vector<LabelledFeature>& features,
                                             const cv::Mat& mask);

// |A and B| / |A or B| of the non-zero pixels; 1 when both are empty.
double RegionIoU(const cv::Mat& predicted, const cv::Mat& truth);

// A binary mask (CV_8U, 255 inside) of the union of polygons (e.g. convex hulls of the
// features of each moving object).
cv::Mat RasterizePolygons(const std::vector<std::vector<cv::Point2f>>& polygons, cv::Size size);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_SEGMENTATION_METRICS_H_
