// make_test_images DIR N WIDTH HEIGHT: writes N deterministic BGR PNG images
// (000000.png ...) for the integration scripts.

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "drivers/camera/camera_test_util.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: make_test_images DIR N WIDTH HEIGHT\n");
    return 2;
  }
  const std::string dir = argv[1];
  const int n = std::atoi(argv[2]), w = std::atoi(argv[3]), h = std::atoi(argv[4]);
  if (n <= 0 || w <= 0 || h <= 0) {
    std::fprintf(stderr, "make_test_images: N, WIDTH and HEIGHT must be positive\n");
    return 2;
  }
  std::filesystem::create_directories(dir);
  for (int i = 0; i < n; ++i) {
    const std::string path = dir + "/" + mbslam::testing_util::FrameName(i, ".png");
    if (!cv::imwrite(path, mbslam::testing_util::MakeTestImage(w, h, 3, i))) {
      std::fprintf(stderr, "make_test_images: cannot write %s\n", path.c_str());
      return 1;
    }
  }
  return 0;
}
