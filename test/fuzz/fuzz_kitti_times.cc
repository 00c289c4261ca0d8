// Fuzz target: the KITTI indexers (IndexKitti): odometry layout (image_2/ + times.txt,
// truth from ../../poses/<seq>.txt) and raw layout (image_02/data/ +
// image_02/timestamps.txt, "YYYY-MM-DD hh:mm:ss.fffffffff"). Three images each.
// Input: records (fuzz_util.h); tag % 3 = 0 times.txt, 1 poses/00.txt,
// 2 timestamps.txt.
//
// Properties: nothing throws or crashes; an accepted index has increasing times and
// finite truth poses.

#include <cstdio>
#include <string>

#include "test/fuzz/dataset_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using mbslam::fuzz::ScratchDir;
  static const bool layout = [] {
    mbslam::fuzz::QuietLogs();
    ScratchDir& s = ScratchDir::Get();
    s.MakeDir("kitti/sequences/00/image_2");
    s.MakeDir("kitti/poses");
    s.MakeDir("kitti_raw/image_02/data");
    for (const char* f : {"000000.png", "000001.png", "000002.png"}) {
      s.Touch(std::string("kitti/sequences/00/image_2/") + f);
      s.Touch(std::string("kitti_raw/image_02/data/") + f);
    }
    return true;
  }();
  (void)layout;
  ScratchDir& s = ScratchDir::Get();
  static const char* const kFiles[3] = {"kitti/sequences/00/times.txt", "kitti/poses/00.txt",
                                        "kitti_raw/image_02/timestamps.txt"};
  for (const char* f : kFiles) std::remove((s.path() + "/" + f).c_str());
  for (const mbslam::fuzz::Record& r : mbslam::fuzz::SplitRecords(data, size, 3)) {
    s.Write(kFiles[r.tag % 3], r.data, r.size);
  }
  mbslam::FolderOptions options;  // kitti_camera = 2
  for (const char* dir : {"/kitti/sequences/00", "/kitti_raw"}) {
    mbslam::ImageIndex index;
    if (mbslam::IndexKitti(s.path() + dir, options, &index).ok()) mbslam::fuzz::CheckIndex(index);
  }
  return 0;
}
