#ifndef MBSLAM_COMMON_UTIL_STATISTICS_H_
#define MBSLAM_COMMON_UTIL_STATISTICS_H_

// Small robust statistics shared by the algorithm layers.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace mbslam {

// The median of v (the upper one of an even count); 0 for an empty v.
inline double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_STATISTICS_H_
