#ifndef MBSLAM_COMMON_UTIL_STATISTICS_H_
#define MBSLAM_COMMON_UTIL_STATISTICS_H_

// Small robust statistics shared by the algorithm layers.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

namespace mbslam {

// The median of v (the upper one of an even count); 0 for an empty v.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

// The median of v as reports give it: the mean of the two middle values of an even
// count; 0 for an empty v.
inline double MedianOfReport(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

// The median absolute deviation of v about `centre`. kMadToSigma times it is the
// standard deviation of a normal distribution.
inline double MedianAbsoluteDeviation(const std::vector<double>& v, double centre) {
  std::vector<double> dev;
  dev.reserve(v.size());
  for (double x : v) dev.push_back(std::abs(x - centre));
  return Median(std::move(dev));
}
constexpr double kMadToSigma = 1.4826;

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_STATISTICS_H_
