// Known answers for the segmentation metrics (issue 3, "what it must show" 2): a
// labelling with k known errors gives k / N misclassification, with permuted labels and
// with different numbers of predicted and true groups.

#include "tools/eval/segmentation_metrics.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <set>

#include "tools/eval/perturb.h"

namespace mbslam {
namespace eval {
namespace {

std::vector<int> Groups(const std::vector<int>& sizes) {
  std::vector<int> labels;
  for (size_t g = 0; g < sizes.size(); ++g) {
    labels.insert(labels.end(), static_cast<size_t>(sizes[g]), static_cast<int>(g + 1));
  }
  return labels;
}

// Independent check: the best count of correctly labelled points over every one-to-one
// mapping of predicted to true labels (brute force over permutations).
int BruteForceErrors(const std::vector<int>& pred, const std::vector<int>& truth) {
  std::vector<int> p_labels, t_labels;
  for (int v : pred) {
    if (v >= 0 && std::find(p_labels.begin(), p_labels.end(), v) == p_labels.end()) {
      p_labels.push_back(v);
    }
  }
  for (int v : truth) {
    if (std::find(t_labels.begin(), t_labels.end(), v) == t_labels.end()) {
      t_labels.push_back(v);
    }
  }
  const size_t n = std::max(p_labels.size(), t_labels.size());
  std::vector<int> perm(n);
  std::iota(perm.begin(), perm.end(), 0);
  int best = 0;
  do {
    int correct = 0;
    for (size_t i = 0; i < pred.size(); ++i) {
      if (pred[i] < 0) {
        continue;
      }
      const size_t pi = static_cast<size_t>(std::find(p_labels.begin(), p_labels.end(), pred[i]) -
                                            p_labels.begin());
      const int t = perm[pi];
      if (t < static_cast<int>(t_labels.size()) && t_labels[static_cast<size_t>(t)] == truth[i]) {
        ++correct;
      }
    }
    best = std::max(best, correct);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return static_cast<int>(pred.size()) - best;
}

TEST(Misclassification, PerfectUnderAnyPermutation) {
  const std::vector<int> truth = Groups({40, 25, 10});
  std::vector<int> pred = truth;
  for (int& v : pred) {
    v = (v == 1) ? 7 : (v == 2 ? 3 : 5);
  }
  const auto r = Misclassification(pred, truth);
  EXPECT_EQ(r.num_errors, 0);
  EXPECT_DOUBLE_EQ(r.rate, 0.0);
  EXPECT_EQ(r.pred_to_true.at(7), 1);
  EXPECT_EQ(r.pred_to_true.at(3), 2);
  EXPECT_EQ(r.pred_to_true.at(5), 3);
}

TEST(Misclassification, KnownErrorsGiveKOverN) {
  const std::vector<int> truth = Groups({120, 80, 60});
  for (int k : {1, 5, 12, 25}) {
    for (uint64_t seed = 1; seed <= 5; ++seed) {
      LabelPerturbation p;
      p.wrong = k;
      p.seed = seed;
      std::vector<int> pred;
      int expected = -1;
      ASSERT_TRUE(PerturbLabels(truth, p, &pred, &expected).ok());
      EXPECT_EQ(expected, k);
      const auto r = Misclassification(pred, truth);
      EXPECT_EQ(r.num_errors, k);
      EXPECT_DOUBLE_EQ(r.rate, static_cast<double>(k) / truth.size());
      EXPECT_EQ(r.num_errors, BruteForceErrors(pred, truth));
    }
  }
}

TEST(Misclassification, DifferentGroupCounts) {
  const std::vector<int> truth = Groups({100, 60, 30, 20});
  // More predicted groups: 15 points of the largest group split off.
  LabelPerturbation split;
  split.split = 15;
  std::vector<int> pred;
  int expected = 0;
  ASSERT_TRUE(PerturbLabels(truth, split, &pred, &expected).ok());
  auto r = Misclassification(pred, truth);
  EXPECT_EQ(r.num_pred_groups, 5);
  EXPECT_EQ(r.num_true_groups, 4);
  EXPECT_EQ(r.num_errors, 15);
  EXPECT_EQ(r.num_errors, BruteForceErrors(pred, truth));
  // Fewer predicted groups: the two smallest merged (the 20 points are wrong).
  LabelPerturbation merge;
  merge.merge_smallest = true;
  ASSERT_TRUE(PerturbLabels(truth, merge, &pred, &expected).ok());
  r = Misclassification(pred, truth);
  EXPECT_EQ(r.num_pred_groups, 3);
  EXPECT_EQ(expected, 20);
  EXPECT_EQ(r.num_errors, 20);
  EXPECT_EQ(r.num_errors, BruteForceErrors(pred, truth));
  // All at once, with wrong labels on top.
  LabelPerturbation all;
  all.split = 10;
  all.merge_smallest = true;
  all.wrong = 7;
  all.seed = 9;
  ASSERT_TRUE(PerturbLabels(truth, all, &pred, &expected).ok());
  EXPECT_EQ(expected, 10 + 20 + 7);
  r = Misclassification(pred, truth);
  EXPECT_EQ(r.num_errors, expected);
  EXPECT_EQ(r.num_errors, BruteForceErrors(pred, truth));
  // Everything in one predicted group: only the largest true group is right.
  r = Misclassification(std::vector<int>(truth.size(), 42), truth);
  EXPECT_EQ(r.num_errors, 110);
  // Unassigned points (negative labels) are errors.
  std::vector<int> partial = truth;
  partial[0] = partial[150] = -1;
  r = Misclassification(partial, truth);
  EXPECT_EQ(r.num_errors, 2);
  // Requests that could change the optimal matching are refused.
  LabelPerturbation too_many;
  too_many.wrong = 15;
  EXPECT_FALSE(PerturbLabels(truth, too_many, &pred, &expected).ok());
}

TEST(MovingFeatures, PrecisionRecall) {
  cv::Mat mask(100, 100, CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(20, 20, 30, 30)).setTo(255);
  std::vector<LabelledFeature> f = {
      {25, 25, true},   // TP
      {30, 40, true},   // TP
      {80, 80, true},   // FP
      {35, 35, false},  // FN
      {5, 5, false},    // TN
      {500, 5, true},   // outside the image: ignored
  };
  const PrecisionRecall pr = MovingFeaturePrecisionRecall(f, mask);
  EXPECT_EQ(pr.true_positives, 2);
  EXPECT_EQ(pr.false_positives, 1);
  EXPECT_EQ(pr.false_negatives, 1);
  EXPECT_EQ(pr.true_negatives, 1);
  EXPECT_DOUBLE_EQ(pr.precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(pr.recall, 2.0 / 3.0);
  // 16-bit body-id masks (the simulator's) work the same.
  cv::Mat ids;
  mask.convertTo(ids, CV_16U);
  EXPECT_EQ(MovingFeaturePrecisionRecall(f, ids).true_positives, 2);
  PrecisionRecall sum = pr;
  sum.Add(pr);
  EXPECT_EQ(sum.true_positives, 4);
  EXPECT_DOUBLE_EQ(sum.precision, 2.0 / 3.0);
}

TEST(Regions, IouAndPolygons) {
  cv::Mat a(50, 50, CV_8UC1, cv::Scalar(0)), b = a.clone();
  a(cv::Rect(0, 0, 20, 10)).setTo(1);
  b(cv::Rect(10, 0, 20, 10)).setTo(255);
  EXPECT_DOUBLE_EQ(RegionIoU(a, b), 100.0 / 300.0);
  EXPECT_DOUBLE_EQ(RegionIoU(a, a), 1.0);
  EXPECT_DOUBLE_EQ(RegionIoU(cv::Mat::zeros(5, 5, CV_8U), cv::Mat::zeros(5, 5, CV_8U)), 1.0);
  // A square hull from (9.5, 9.5) to (19.5, 19.5) covers the pixel centres 10..19.
  const cv::Mat hull = RasterizePolygons(
      {{{9.5f, 9.5f}, {19.5f, 9.5f}, {19.5f, 19.5f}, {9.5f, 19.5f}}}, cv::Size(30, 30));
  EXPECT_NEAR(cv::countNonZero(hull), 100, 22);
  EXPECT_EQ(hull.at<uint8_t>(15, 15), 255);
  EXPECT_EQ(hull.at<uint8_t>(25, 25), 0);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
