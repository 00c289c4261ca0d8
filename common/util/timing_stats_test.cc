#include "common/util/timing_stats.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

TEST(Percentile, InterpolatesOrderStatistics) {
  std::vector<double> v = {5, 1, 4, 2, 3};
  EXPECT_DOUBLE_EQ(Percentile(&v, 50), 3.0);
  EXPECT_DOUBLE_EQ(Percentile(&v, 0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(&v, 100), 5.0);
  EXPECT_DOUBLE_EQ(Percentile(&v, 25), 2.0);
  std::vector<double> two = {0, 10};
  EXPECT_DOUBLE_EQ(Percentile(&two, 99), 9.9);
  std::vector<double> empty;
  EXPECT_DOUBLE_EQ(Percentile(&empty, 50), 0.0);
}

TEST(TimingStats, SummarisesAndResetsPerPeriod) {
  TimingStats stats("stage", /*budget_ms=*/5.0);
  for (int i = 1; i <= 100; ++i) stats.Add(i * 0.1);  // 0.1 .. 10 ms
  const TimingSummary s = stats.Drain();
  EXPECT_EQ(s.count, 100);
  EXPECT_NEAR(s.mean_ms, 5.05, 1e-9);
  EXPECT_NEAR(s.p50_ms, 5.05, 1e-9);
  EXPECT_NEAR(s.p99_ms, 9.901, 1e-9);
  EXPECT_DOUBLE_EQ(s.max_ms, 10.0);
  EXPECT_EQ(s.overruns, 50);  // 5.1 .. 10.0
  const TimingSummary empty = stats.Drain();
  EXPECT_EQ(empty.count, 0);
  EXPECT_EQ(stats.total_count(), 100);
}

TEST(TimingStats, CumulativeSurvivesDrainsAndStaysBounded) {
  TimingStats stats("stage", 0.0, /*max_samples=*/16);
  for (int i = 0; i < 1000; ++i) {
    stats.Add(i < 500 ? 1.0 : 3.0);
    if (i % 100 == 0) stats.Drain();
  }
  const TimingSummary all = stats.Cumulative();
  EXPECT_EQ(all.count, 1000);
  EXPECT_DOUBLE_EQ(all.mean_ms, 2.0);
  EXPECT_DOUBLE_EQ(all.max_ms, 3.0);
  EXPECT_DOUBLE_EQ(all.p99_ms, 3.0);
}

TEST(TimingStats, ReservoirIsBounded) {
  TimingStats stats("stage", 0.0, /*max_samples=*/8);
  for (int i = 0; i < 100; ++i) stats.Add(1.0);
  const TimingSummary s = stats.Drain();
  EXPECT_EQ(s.count, 100);
  EXPECT_DOUBLE_EQ(s.p99_ms, 1.0);
}

}  // namespace
}  // namespace mbslam
