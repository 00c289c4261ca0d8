#ifndef MBSLAM_COMMON_UTIL_PARALLEL_FOR_H_
#define MBSLAM_COMMON_UTIL_PARALLEL_FOR_H_

// Runs f(i) for i in [0, n) split into up to `threads` contiguous chunks, the first on
// the calling thread, the others on short-lived threads; returns when all are done.
// For independent work items (each touching only its own state), so the result does
// not depend on the split: the same as a plain loop.
//
//   ParallelFor(filters.size(), options.threads, [&](size_t i) { filters[i].Update(); });

#include <algorithm>
#include <cstddef>
#include <future>
#include <vector>

namespace mbslam {

template <typename F>
void ParallelFor(size_t n, int threads, F&& f) {
  const size_t chunks = std::min<size_t>(n, static_cast<size_t>(std::max(1, threads)));
  if (chunks <= 1) {
    for (size_t i = 0; i < n; ++i) f(i);
    return;
  }
  auto run = [&f](size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) f(i);
  };
  std::vector<std::future<void>> jobs;
  jobs.reserve(chunks - 1);
  for (size_t c = 1; c < chunks; ++c) jobs.push_back(std::async(std::launch::async, run, n * c / chunks, n * (c + 1) / chunks));
  run(0, n / chunks);
  for (auto& j : jobs) j.get();
}

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_PARALLEL_FOR_H_
