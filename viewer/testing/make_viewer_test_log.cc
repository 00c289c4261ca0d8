// Writes a synthetic LCM log of the perception outputs (and camera images) for the
// viewer's integration test, its evaluation and demos.
//
//   make_viewer_test_log OUT.lcmlog [--frames N] [--size WxH] [--jpeg] [--up-to-scale] [--faults]

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "common/util/command_line.h"
#include "viewer/testing/synthetic_outputs.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: make_viewer_test_log OUT.lcmlog [--frames N] [--size WxH] [--jpeg] "
                 "[--up-to-scale] [--faults]\n");
    return 2;
  }
  mbslam::viewer::testing::SyntheticOptions options;
  bool faults = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) {
      int64_t frames = 0;
      const mbslam::Status st = mbslam::ParseInt64(argv[++i], "--frames", &frames);
      if (!st.ok() || frames < 1 || frames > 100000) {
        std::fprintf(stderr, "make_viewer_test_log: %s\n",
                     st.ok() ? "--frames must be 1-100000" : st.message().c_str());
        return 2;
      }
      options.frames = static_cast<int>(frames);
    } else if (a == "--size" && i + 1 < argc) {
      const mbslam::Status st = mbslam::ParseImageSize(argv[++i], "--size", &options.width, &options.height);
      if (!st.ok()) {
        std::fprintf(stderr, "make_viewer_test_log: %s\n", st.message().c_str());
        return 2;
      }
    } else if (a == "--jpeg") {
      options.jpeg = true;
    } else if (a == "--up-to-scale") {
      options.metric = false;
    } else if (a == "--faults") {
      faults = true;
    } else {
      std::fprintf(stderr, "make_viewer_test_log: unknown argument %s\n", a.c_str());
      return 2;
    }
  }
  if (options.frames <= 0 || options.width < 64 || options.height < 48 || options.width > 4096 ||
      options.height > 4096) {
    std::fprintf(stderr, "make_viewer_test_log: bad --frames or --size\n");
    return 2;
  }
  int bad = 0;
  const mbslam::Status s = mbslam::viewer::testing::WriteSyntheticLog(
      argv[1], options, mbslam::ChannelOptions(), faults, &bad);
  if (!s.ok()) {
    std::fprintf(stderr, "make_viewer_test_log: %s\n", s.message().c_str());
    return 1;
  }
  std::printf("%s: %d frames, %d bad messages\n", argv[1], options.frames, bad);
  return 0;
}
