#ifndef MBSLAM_TEST_FUZZ_LCM_TYPES_H_
#define MBSLAM_TEST_FUZZ_LCM_TYPES_H_

// Message types by index, in the order of MBSLAM_FOR_EACH_LCM_TYPE: a fuzz input's tag
// byte selects a type by its index (modulo the count); the seed tool writes the same.

#include <string>

#include "common/lcm/all_types.h"

namespace mbslam {
namespace fuzz {

#define MBSLAM_FUZZ_COUNT_ONE(t) +1
inline constexpr int kNumLcmTypes = 0 MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_FUZZ_COUNT_ONE);
#undef MBSLAM_FUZZ_COUNT_ONE

// The index of a type name ("image_t"), or -1.
inline int LcmTypeIndex(const std::string& name) {
  int i = 0;
#define MBSLAM_FUZZ_MATCH(t) \
  if (name == #t) return i;  \
  ++i;
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_FUZZ_MATCH)
#undef MBSLAM_FUZZ_MATCH
  return -1;
}

}  // namespace fuzz
}  // namespace mbslam

#endif  // MBSLAM_TEST_FUZZ_LCM_TYPES_H_
