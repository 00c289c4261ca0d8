// Fuzz target: the TUM RGB-D indexer (IndexTumSequence): rgb.txt, groundtruth.txt
// (interpolated to the image times) and the cut-down layout's truth_cam_poses.txt.
// Input: records (fuzz_util.h); tag % 3 = 0 rgb.txt, 1 groundtruth.txt,
// 2 truth_cam_poses.txt (used when there is no rgb.txt; raw_imgs/ holds 3 images).
//
// Properties: nothing throws or crashes; an accepted index has increasing times and
// finite truth poses.

#include <cstdio>
#include <string>

#include "test/fuzz/dataset_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using mbslam::fuzz::ScratchDir;
  static const std::string dir = [] {
    mbslam::fuzz::QuietLogs();
    const std::string d = ScratchDir::Get().MakeDir("tum");
    ScratchDir::Get().MakeDir("tum/raw_imgs");
    for (const char* f : {"tum/raw_imgs/1.png", "tum/raw_imgs/2.png", "tum/raw_imgs/3.png"}) {
      ScratchDir::Get().Touch(f);
    }
    return d;
  }();
  static const char* const kFiles[3] = {"rgb.txt", "groundtruth.txt", "truth_cam_poses.txt"};
  for (const char* f : kFiles) std::remove((dir + "/" + f).c_str());
  for (const mbslam::fuzz::Record& r : mbslam::fuzz::SplitRecords(data, size, 3)) {
    ScratchDir::Get().Write(std::string("tum/") + kFiles[r.tag % 3], r.data, r.size);
  }
  mbslam::ImageIndex index;
  if (mbslam::IndexTumSequence(dir, /*max_gap_s=*/0.1, &index).ok()) {
    mbslam::fuzz::CheckIndex(index);
  }
  return 0;
}
