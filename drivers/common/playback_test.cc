#include "drivers/common/playback.h"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <string>

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

TEST(ProgressBar, DrawsOnATerminal) {
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) GTEST_SKIP() << "no pseudo-terminal";
  FILE* terminal = std::fopen(ptsname(master), "w");
  ASSERT_NE(terminal, nullptr);
  {
    ProgressBar bar(true, terminal);
    EXPECT_TRUE(bar.active());
    bar.Update(5, 10, "bad 0");
    bar.Update(10, 10, "bad 0");  // the last update is always drawn
  }
  std::fclose(terminal);
  fcntl(master, F_SETFL, O_NONBLOCK);
  std::string text;
  char buf[1024];
  for (ssize_t n; (n = read(master, buf, sizeof(buf))) > 0;) text.append(buf, static_cast<size_t>(n));
  close(master);
  EXPECT_NE(text.find("5/10"), std::string::npos) << text;
  EXPECT_NE(text.find("10/10 100.0 %"), std::string::npos) << text;
  EXPECT_NE(text.find("bad 0"), std::string::npos) << text;
}

}  // namespace
}  // namespace mbslam
