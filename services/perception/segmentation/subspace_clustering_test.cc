#include "services/perception/segmentation/subspace_clustering.h"

#include <algorithm>
#include <random>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace mbslam {
namespace {

// Trajectory-like data: `sizes[g]` points on a random 3-dimensional affine subspace per
// group in R^dims, with Gaussian noise.
Eigen::MatrixXd AffineSubspaces(const std::vector<int>& sizes, int dims, double noise, uint32_t seed,
                                std::vector<int>* truth) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  int total = 0;
  for (int s : sizes) total += s;
  Eigen::MatrixXd Y(dims, total);
  truth->clear();
  int col = 0;
  for (size_t g = 0; g < sizes.size(); ++g) {
    Eigen::MatrixXd basis(dims, 3);
    Eigen::VectorXd offset(dims);
    for (int r = 0; r < dims; ++r) {
      offset[r] = 50.0 * n01(rng);
      for (int c = 0; c < 3; ++c) basis(r, c) = 10.0 * n01(rng);
    }
    for (int p = 0; p < sizes[g]; ++p, ++col) {
      Eigen::Vector3d x(n01(rng), n01(rng), n01(rng));
      Y.col(col) = offset + basis * x;
      for (int r = 0; r < dims; ++r) Y(r, col) += noise * n01(rng);
      truth->push_back(static_cast<int>(g));
    }
  }
  return Y;
}

// Share of points misclassified under the best label permutation (k <= 3 here).
double Errors(const std::vector<int>& truth, const std::vector<int>& labels) {
  int k = 0;
  for (int l : labels) k = std::max(k, l + 1);
  for (int l : truth) k = std::max(k, l + 1);
  std::vector<int> perm(static_cast<size_t>(k));
  for (int i = 0; i < k; ++i) perm[static_cast<size_t>(i)] = i;
  size_t best = truth.size();
  do {
    size_t wrong = 0;
    for (size_t i = 0; i < truth.size(); ++i) wrong += perm[static_cast<size_t>(labels[i])] != truth[i];
    best = std::min(best, wrong);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return static_cast<double>(best) / static_cast<double>(truth.size());
}

TEST(SubspaceClustering, TotalResidualIsZeroOnExactSubspacesAndGrowsWhenMerged) {
  std::vector<int> truth;
  const Eigen::MatrixXd Y = AffineSubspaces({30, 30}, 20, 0.0, 1, &truth);
  EXPECT_NEAR(TotalSubspaceResidual(Y, truth, 3) / Y.squaredNorm(), 0.0, 1e-12);
  const std::vector<int> one(truth.size(), 0);
  EXPECT_GT(TotalSubspaceResidual(Y, one, 3), 1.0);
  // Residual per group times its size: a group of two points on a line has none.
  const Eigen::MatrixXd line = (Eigen::MatrixXd(2, 3) << 0, 1, 3, 0, 1, 5).finished();
  EXPECT_NEAR(TotalSubspaceResidual(line, {0, 0, 1}, 1), 0.0, 1e-12);
  EXPECT_GT(TotalSubspaceResidual(line, {0, 0, 0}, 1), 0.01);
}

TEST(SubspaceClustering, NormalizedCutOfBlockAffinity) {
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(4, 4);
  W(0, 1) = W(1, 0) = 1.0;
  W(2, 3) = W(3, 2) = 1.0;
  W(1, 2) = W(2, 1) = 0.5;
  EXPECT_DOUBLE_EQ(NormalizedCut(W, {0, 0, 0, 0}), 0.0);
  // Each side: cut 0.5 over a volume of 2.5.
  EXPECT_NEAR(NormalizedCut(W, {0, 0, 1, 1}), 2 * 0.5 / 2.5, 1e-12);
  // Splitting a well-connected pair costs more than the weak link.
  EXPECT_GT(NormalizedCut(W, {0, 1, 1, 1}), NormalizedCut(W, {0, 0, 1, 1}));
}

TEST(SubspaceClustering, SilhouetteSeparatesMotionsFromASplitMotion) {
  std::vector<int> truth;
  const Eigen::MatrixXd Y = AffineSubspaces({40, 40}, 24, 0.05, 7, &truth);
  EXPECT_GT(SubspaceSilhouette(Y, truth, 3), 0.9);
  // One subspace cut in halves: both halves fit the same subspace.
  std::vector<int> one;
  const Eigen::MatrixXd Z = AffineSubspaces({80}, 24, 0.05, 8, &one);
  std::vector<int> halves(80, 0);
  for (int i = 40; i < 80; ++i) halves[static_cast<size_t>(i)] = 1;
  EXPECT_LT(SubspaceSilhouette(Z, halves, 3), 0.3);
  EXPECT_DOUBLE_EQ(SubspaceSilhouette(Y, std::vector<int>(80, 0), 3), 0.0);
}

TEST(SubspaceClustering, KnownGroupCountSeparatesSubspaces) {
  std::vector<int> truth;
  const Eigen::MatrixXd Y = AffineSubspaces({40, 30, 25}, 24, 0.05, 2, &truth);
  SubspaceClusteringOptions o;
  ASSERT_TRUE(o.Check());
  int k_used = 0;
  const std::vector<int> labels = ClusterTrajectories(Y, 3, o, &k_used);
  EXPECT_EQ(k_used, 3);
  EXPECT_LE(Errors(truth, labels), 0.02);
}

TEST(SubspaceClustering, HypothesisSelectionKeepsTheBestFittingOne) {
  std::vector<int> truth;
  const Eigen::MatrixXd Y = AffineSubspaces({30, 30}, 20, 0.05, 3, &truth);
  SubspaceClusteringOptions o;
  const Eigen::MatrixXd C = SparseSelfExpression(Y, o);
  double best = 0.0;
  const std::vector<int> labels = SegmentByHypotheses(Y, C, 2, o, &best);
  EXPECT_NEAR(best, TotalSubspaceResidual(Y, labels, o.selection_dimension), 1e-9 * (1.0 + best));
  for (double mass : o.coefficient_masses) {
    SubspaceClusteringOptions single = o;
    single.coefficient_masses = {mass};
    double r = 0.0;
    SegmentByHypotheses(Y, C, 2, single, &r);
    EXPECT_LE(best, r + 1e-9 * (1.0 + r));
  }
  EXPECT_LE(Errors(truth, labels), 0.02);
}

TEST(SubspaceClustering, SelectsTheNumberOfMotions) {
  for (const std::string order : {"silhouette", "cut"}) {
  SubspaceClusteringOptions o;
  o.order_selection = order;
  for (const std::vector<int>& sizes : std::vector<std::vector<int>>{{60}, {40, 35}, {40, 30, 30}}) {
    std::vector<int> truth;
    const Eigen::MatrixXd Y = AffineSubspaces(sizes, 24, 0.05, 4, &truth);
    int k = 0;
    const std::vector<int> labels = ClusterTrajectories(Y, 0, o, &k);
    EXPECT_EQ(k, static_cast<int>(sizes.size())) << order;
    EXPECT_LE(Errors(truth, labels), 0.05) << order;
  }
  }
}

}  // namespace
}  // namespace mbslam
