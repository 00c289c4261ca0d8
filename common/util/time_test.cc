#include "common/util/time.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

TEST(Time, ConversionsRoundTrip) {
  EXPECT_EQ(SecondsToUtime(1.5), 1500000);
  EXPECT_EQ(SecondsToUtime(-0.0000014), -1);
  EXPECT_DOUBLE_EQ(UtimeToSeconds(2500000), 2.5);
  EXPECT_EQ(SecondsToUtime(UtimeToSeconds(1700000000123456)), 1700000000123456);
  EXPECT_DOUBLE_EQ(UtimeToMs(1500), 1.5);
}

TEST(Time, MonotonicNeverGoesBack) {
  int64_t last = MonotonicUtime();
  for (int i = 0; i < 1000; ++i) {
    const int64_t now = MonotonicUtime();
    EXPECT_GE(now, last);
    last = now;
  }
  EXPECT_GT(WallUtime(), SecondsToUtime(1.6e9));  // after 2020
}

}  // namespace
}  // namespace mbslam
