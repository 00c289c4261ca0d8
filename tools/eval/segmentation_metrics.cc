#include "tools/eval/segmentation_metrics.h"

#include <opencv2/imgproc.hpp>

#include <cmath>

#include "tools/eval/hungarian.h"

namespace mbslam {
namespace eval {

MisclassificationResult Misclassification(const std::vector<int>& predicted,
                                          const std::vector<int>& truth) {
  MisclassificationResult r;
  const size_t n = std::min(predicted.size(), truth.size());
  r.num_points = static_cast<int>(n);
  std::map<int, int> pred_index, true_index;
  for (size_t i = 0; i < n; ++i) {
    if (predicted[i] >= 0) {
      pred_index.emplace(predicted[i], 0);
    }
    true_index.emplace(truth[i], 0);
  }
  int k = 0;
  for (auto& p : pred_index) {
    p.second = k++;
  }
  k = 0;
  for (auto& t : true_index) {
    t.second = k++;
  }
  r.num_pred_groups = static_cast<int>(pred_index.size());
  r.num_true_groups = static_cast<int>(true_index.size());
  if (n == 0) {
    return r;
  }
  // Contingency table: points of predicted group p in true group t.
  Eigen::MatrixXd counts = Eigen::MatrixXd::Zero(r.num_pred_groups, r.num_true_groups);
  for (size_t i = 0; i < n; ++i) {
    if (predicted[i] < 0) {
      continue;
    }
    counts(pred_index[predicted[i]], true_index[truth[i]]) += 1.0;
  }
  double matched = 0.0;
  const std::vector<int> assignment = SolveMaxAssignment(counts, &matched);
  std::vector<int> pred_labels(pred_index.size()), true_labels(true_index.size());
  for (const auto& p : pred_index) {
    pred_labels[static_cast<size_t>(p.second)] = p.first;
  }
  for (const auto& t : true_index) {
    true_labels[static_cast<size_t>(t.second)] = t.first;
  }
  for (size_t p = 0; p < assignment.size(); ++p) {
    if (assignment[p] >= 0) {
      r.pred_to_true[pred_labels[p]] = true_labels[static_cast<size_t>(assignment[p])];
    }
  }
  r.num_errors = r.num_points - static_cast<int>(std::lround(matched));
  r.rate = static_cast<double>(r.num_errors) / static_cast<double>(r.num_points);
  return r;
}

void PrecisionRecall::Finish() {
  const int predicted = true_positives + false_positives;
  const int actual = true_positives + false_negatives;
  precision = predicted > 0 ? static_cast<double>(true_positives) / predicted : 1.0;
  recall = actual > 0 ? static_cast<double>(true_positives) / actual : 1.0;
  f1 = precision + recall > 0.0 ? 2.0 * precision * recall / (precision + recall) : 0.0;
}

void PrecisionRecall::Add(const PrecisionRecall& o) {
  true_positives += o.true_positives;
  false_positives += o.false_positives;
  false_negatives += o.false_negatives;
  true_negatives += o.true_negatives;
  Finish();
}

PrecisionRecall MovingFeaturePrecisionRecall(const std::vector<LabelledFeature>& features,
                                             const cv::Mat& mask) {
  PrecisionRecall pr;
  for (const auto& f : features) {
    const int x = static_cast<int>(std::lround(f.u)), y = static_cast<int>(std::lround(f.v));
    if (x < 0 || y < 0 || x >= mask.cols || y >= mask.rows) {
      continue;
    }
    bool inside = false;
    switch (mask.depth()) {
      case CV_8U:
        inside = mask.ptr<uint8_t>(y)[static_cast<ptrdiff_t>(x) * mask.channels()] != 0;
        break;
      case CV_16U:
        inside = mask.ptr<uint16_t>(y)[static_cast<ptrdiff_t>(x) * mask.channels()] != 0;
        break;
      default:
        inside = mask.at<float>(y, x) != 0.0f;
        break;
    }
    if (f.moving && inside) {
      ++pr.true_positives;
    } else if (f.moving && !inside) {
      ++pr.false_positives;
    } else if (!f.moving && inside) {
      ++pr.false_negatives;
    } else {
      ++pr.true_negatives;
    }
  }
  pr.Finish();
  return pr;
}

double RegionIoU(const cv::Mat& predicted, const cv::Mat& truth) {
  CV_Assert(predicted.size() == truth.size());
  cv::Mat a = predicted, b = truth;
  if (a.channels() > 1) {
    cv::cvtColor(a, a, cv::COLOR_BGR2GRAY);
  }
  if (b.channels() > 1) {
    cv::cvtColor(b, b, cv::COLOR_BGR2GRAY);
  }
  const cv::Mat pa = a != 0, pb = b != 0;
  const int inter = cv::countNonZero(pa & pb);
  const int uni = cv::countNonZero(pa | pb);
  return uni == 0 ? 1.0 : static_cast<double>(inter) / static_cast<double>(uni);
}

cv::Mat RasterizePolygons(const std::vector<std::vector<cv::Point2f>>& polygons, cv::Size size) {
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  for (const auto& poly : polygons) {
    if (poly.size() < 3) {
      continue;
    }
    // Fixed point with 4 fractional bits for sub-pixel vertices.
    std::vector<cv::Point> pts;
    pts.reserve(poly.size());
    for (const auto& p : poly) {
      pts.emplace_back(cvRound(p.x * 16.0f), cvRound(p.y * 16.0f));
    }
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{pts}, cv::Scalar(255), cv::LINE_8, 4);
  }
  return mask;
}

}  // namespace eval
}  // namespace mbslam
