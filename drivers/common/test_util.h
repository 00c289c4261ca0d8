#ifndef MBSLAM_DRIVERS_COMMON_TEST_UTIL_H_
#define MBSLAM_DRIVERS_COMMON_TEST_UTIL_H_

// Small helpers for the drivers' tests: temporary folders and text files.

#include <fstream>
#include <string>

#include "common/testing/temp_dir.h"

namespace mbslam {
namespace testing_util {

// A new folder mbslam_<tag>_XXXXXX, removed when the test process exits.
inline std::string MakeTempDir(const std::string& tag) { return MakeTestTempDir(tag); }

inline void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_TEST_UTIL_H_
