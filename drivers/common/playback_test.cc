#include "drivers/common/playback.h"

#include <gtest/gtest.h>

#include <cstdio>

#include "common/util/time.h"

namespace mbslam {
namespace {

TEST(PlaybackClock, AsFastAsPossibleNeverWaits) {
  PlaybackClock clock(0.0);
  const int64_t start = MonotonicUtime();
  for (int i = 0; i < 100; ++i) ASSERT_TRUE(clock.WaitUntil(int64_t{i} * 1000000));
  EXPECT_LT(MonotonicUtime() - start, 50000);
}

TEST(PlaybackClock, PacesAtTheRequestedSpeed) {
  PlaybackClock clock(4.0);
  const int64_t start = MonotonicUtime();
  for (int i = 0; i <= 10; ++i) ASSERT_TRUE(clock.WaitUntil(5000000 + int64_t{i} * 100000));
  // 1 s of message time at 4x: 250 ms of wall time.
  const int64_t elapsed = MonotonicUtime() - start;
  EXPECT_GE(elapsed, 245000);
  EXPECT_LT(elapsed, 600000);
}

TEST(PlaybackClock, TimeGoingBackwardsRestartsTheSchedule) {
  PlaybackClock clock(1.0);
  ASSERT_TRUE(clock.WaitUntil(10000000));
  const int64_t start = MonotonicUtime();
  ASSERT_TRUE(clock.WaitUntil(0));  // earlier: no wait, new origin
  ASSERT_TRUE(clock.WaitUntil(50000));
  const int64_t elapsed = MonotonicUtime() - start;
  EXPECT_GE(elapsed, 45000);
  EXPECT_LT(elapsed, 400000);
}

TEST(ProgressBar, DrawsNothingWhenNotATerminal) {
  FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    ProgressBar bar(true, f);
    EXPECT_FALSE(bar.active());
    bar.Update(5, 10);
    bar.Finish();
  }
  EXPECT_EQ(std::ftell(f), 0);
  std::fclose(f);
}

}  // namespace
}  // namespace mbslam
