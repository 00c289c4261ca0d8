#include "tools/tracks/misclassification.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

TEST(Misclassification, KnownAnswers) {
  const std::vector<int> truth = {0, 0, 0, 0, 1, 1, 1, 1, 2, 2};
  EXPECT_DOUBLE_EQ(Misclassification(truth, truth), 0.0);
  // Permuted labels are not errors.
  EXPECT_DOUBLE_EQ(Misclassification(truth, {5, 5, 5, 5, 7, 7, 7, 7, 9, 9}), 0.0);
  // k = 2 wrong labels out of 10.
  EXPECT_DOUBLE_EQ(Misclassification(truth, {1, 1, 1, 2, 0, 0, 0, 1, 2, 2}), 0.2);
  // Too few predicted groups: a whole true group is wrong.
  EXPECT_DOUBLE_EQ(Misclassification(truth, {0, 0, 0, 0, 1, 1, 1, 1, 1, 1}), 0.2);
  // Too many: the extra group's members are wrong.
  EXPECT_DOUBLE_EQ(Misclassification(truth, {0, 0, 0, 3, 1, 1, 1, 1, 2, 2}), 0.1);
}

TEST(Hungarian, SolvesSmallAssignment) {
  const std::vector<std::vector<double>> cost = {{4, 1, 3}, {2, 0, 5}, {3, 2, 2}};
  const std::vector<int> a = HungarianAssignment(cost);
  EXPECT_EQ(a, (std::vector<int>{1, 0, 2}));
}

}  // namespace
}  // namespace mbslam
