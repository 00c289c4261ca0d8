#ifndef MBSLAM_DRIVERS_COMMON_TEST_UTIL_H_
#define MBSLAM_DRIVERS_COMMON_TEST_UTIL_H_

// Small helpers for the drivers' tests: temporary folders and text files.

#include <stdlib.h>

#include <fstream>
#include <string>
#include <vector>

namespace mbslam {
namespace testing_util {

inline std::string MakeTempDir(const std::string& tag) {
  std::string pattern = "/tmp/mbslam_" + tag + "_XXXXXX";
  std::vector<char> buf(pattern.begin(), pattern.end());
  buf.push_back('\0');
  const char* dir = mkdtemp(buf.data());
  return dir ? std::string(dir) : std::string();
}

inline void WriteTextFile(const std::string& path, const std::string& text) {
  std::ofstream(path) << text;
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_TEST_UTIL_H_
