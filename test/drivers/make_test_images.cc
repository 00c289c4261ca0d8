// make_test_images DIR N WIDTH HEIGHT: writes N deterministic BGR PNG images
// (000000.png ...) for the integration scripts.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <tuple>
#include <opencv2/imgcodecs.hpp>

#include "common/util/command_line.h"
#include "drivers/camera/camera_test_util.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: make_test_images DIR N WIDTH HEIGHT\n");
    return 2;
  }
  const std::string dir = argv[1];
  int64_t n = 0, w = 0, h = 0;
  for (const auto& [text, what, value] : {std::make_tuple(argv[2], "N", &n), std::make_tuple(argv[3], "WIDTH", &w),
                                          std::make_tuple(argv[4], "HEIGHT", &h)}) {
    const mbslam::Status s = mbslam::ParseInt64(text, what, value);
    if (!s.ok()) {
      std::fprintf(stderr, "make_test_images: %s\n", s.message().c_str());
      return 2;
    }
  }
  if (n <= 0 || w <= 0 || h <= 0 || n > 100000 || w > 8192 || h > 8192) {
    std::fprintf(stderr, "make_test_images: N must be 1-100000, WIDTH and HEIGHT 1-8192\n");
    return 2;
  }
  std::filesystem::create_directories(dir);
  for (int i = 0; i < static_cast<int>(n); ++i) {
    const std::string path = dir + "/" + mbslam::testing_util::FrameName(i, ".png");
    if (!cv::imwrite(path, mbslam::testing_util::MakeTestImage(static_cast<int>(w), static_cast<int>(h), 3, i))) {
      std::fprintf(stderr, "make_test_images: cannot write %s\n", path.c_str());
      return 1;
    }
  }
  return 0;
}
