#include "common/util/statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace mbslam {
namespace {

TEST(Statistics, MedianIsTheUpperMiddleOfAnEvenCount) {
  EXPECT_EQ(Median({}), 0.0);
  EXPECT_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 3.0);
}

TEST(Statistics, MedianOfReportAveragesTheMiddlePairOfAnEvenCount) {
  EXPECT_EQ(MedianOfReport({}), 0.0);
  EXPECT_EQ(MedianOfReport({5.0}), 5.0);
  EXPECT_EQ(MedianOfReport({3.0, 1.0, 2.0}), 2.0);
  EXPECT_EQ(MedianOfReport({4.0, 1.0, 3.0, 2.0}), 2.5);
}

TEST(Statistics, MedianAbsoluteDeviation) {
  EXPECT_EQ(MedianAbsoluteDeviation({1.0, 2.0, 3.0, 4.0, 100.0}, 3.0), 1.0);  // deviations 2 1 0 1 97
  // Deviations 1.5 0.5 0.5 1.5: the upper middle, as Median.
  EXPECT_EQ(MedianAbsoluteDeviation({1.0, 2.0, 3.0, 4.0}, 2.5), 1.5);
}

}  // namespace
}  // namespace mbslam
