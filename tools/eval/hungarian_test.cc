#include "tools/eval/hungarian.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

namespace mbslam {
namespace eval {
namespace {

// Best assignment by enumerating every injection of the smaller side into the larger.
double BruteForce(const Eigen::MatrixXd& cost) {
  const int r = static_cast<int>(cost.rows()), c = static_cast<int>(cost.cols());
  const int n = std::max(r, c);
  std::vector<int> perm(static_cast<size_t>(n));
  std::iota(perm.begin(), perm.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {
    double total = 0.0;
    for (int i = 0; i < r; ++i) {
      const int j = perm[static_cast<size_t>(i)];
      if (j < c) {
        total += cost(i, j);
      }
    }
    best = std::min(best, total);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

TEST(Hungarian, MatchesBruteForceOnRandomRectangularProblems) {
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> size(1, 6);
  std::uniform_real_distribution<double> value(-5.0, 10.0);
  for (int trial = 0; trial < 300; ++trial) {
    const int r = size(rng), c = size(rng);
    Eigen::MatrixXd cost(r, c);
    for (int i = 0; i < r; ++i) {
      for (int j = 0; j < c; ++j) {
        cost(i, j) = (trial % 3 == 0) ? std::round(value(rng)) : value(rng);
      }
    }
    double total = 0.0;
    const auto assignment = SolveAssignment(cost, &total);
    // A valid assignment: distinct columns, min(r, c) of them.
    std::vector<int> used;
    for (int j : assignment) {
      if (j >= 0) {
        used.push_back(j);
      }
    }
    std::sort(used.begin(), used.end());
    EXPECT_EQ(std::unique(used.begin(), used.end()), used.end());
    EXPECT_EQ(static_cast<int>(used.size()), std::min(r, c));
    double check = 0.0;
    for (int i = 0; i < r; ++i) {
      if (assignment[static_cast<size_t>(i)] >= 0) {
        check += cost(i, assignment[static_cast<size_t>(i)]);
      }
    }
    EXPECT_NEAR(check, total, 1e-9);
    EXPECT_NEAR(total, BruteForce(cost), 1e-9) << "trial " << trial << "\n" << cost;
  }
}

TEST(Hungarian, MaximumWeightAndEdgeCases) {
  Eigen::MatrixXd w(2, 3);
  w << 1, 9, 2,  //
      8, 7, 1;
  double total = 0.0;
  const auto a = SolveMaxAssignment(w, &total);
  EXPECT_EQ(a[0], 1);
  EXPECT_EQ(a[1], 0);
  EXPECT_DOUBLE_EQ(total, 17.0);
  EXPECT_TRUE(SolveAssignment(Eigen::MatrixXd(0, 3)).empty());
  const auto none = SolveAssignment(Eigen::MatrixXd(2, 0));
  EXPECT_EQ(none, std::vector<int>({-1, -1}));
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
