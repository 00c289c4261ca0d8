#include "common/util/parallel_for.h"

#include <gtest/gtest.h>

#include <atomic>
#include <numeric>
#include <thread>
#include <vector>

namespace mbslam {
namespace {

TEST(ParallelFor, EveryIndexOnceWhateverTheSplit) {
  for (int threads : {0, 1, 2, 3, 8}) {
    for (size_t n : {0u, 1u, 2u, 5u, 100u}) {
      std::vector<int> hits(n, 0);
      ParallelFor(n, threads, [&](size_t i) { ++hits[i]; });
      for (size_t i = 0; i < n; ++i) EXPECT_EQ(hits[i], 1) << "n " << n << " threads " << threads << " i " << i;
    }
  }
}

TEST(ParallelFor, RunsOnSeveralThreads) {
  std::atomic<int> running{0}, most{0};
  ParallelFor(2, 2, [&](size_t) {
    const int now = ++running;
    int m = most.load();
    while (now > m && !most.compare_exchange_weak(m, now)) {
    }
    // Wait (bounded) for the other chunk to start: both run at once.
    for (int k = 0; k < 2000000 && most.load() < 2; ++k) std::this_thread::yield();
    --running;
  });
  EXPECT_EQ(most.load(), 2);
}

}  // namespace
}  // namespace mbslam
