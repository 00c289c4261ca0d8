#ifndef MBSLAM_COMMON_UTIL_TIME_H_
#define MBSLAM_COMMON_UTIL_TIME_H_

// Time in this project is int64_t microseconds ("utime"). Message time (sensor time)
// drives all logic; the wall and monotonic clocks below are for timing and health only.

#include <chrono>
#include <cmath>
#include <cstdint>

namespace mbslam {

constexpr int64_t kUsecPerSec = 1000000;
constexpr int64_t kUsecPerMsec = 1000;

// Wall clock, µs since the Unix epoch.
inline int64_t WallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Monotonic clock, µs since an arbitrary origin. Use it for durations.
inline int64_t MonotonicUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

inline double UtimeToSeconds(int64_t utime) {
  return static_cast<double>(utime) * 1e-6;
}

// Rounds to the nearest microsecond.
inline int64_t SecondsToUtime(double seconds) {
  return static_cast<int64_t>(std::llround(seconds * 1e6));
}

inline double UtimeToMs(int64_t utime) { return static_cast<double>(utime) * 1e-3; }

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_TIME_H_
