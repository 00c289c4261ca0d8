// Fuzz target: an image folder timed by a timestamps file (IndexImageFolder with
// folder.timestamps_file): per line "<t>" or "<index|file name> <t>". The folder holds
// img1.png, img2.png, img10.png. Input: one byte choosing the unit (s, ms, us, ns),
// then the file.
//
// Properties: nothing throws or crashes; an accepted index has increasing times.

#include <string>

#include "test/fuzz/dataset_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using mbslam::fuzz::ScratchDir;
  static const std::string dir = [] {
    mbslam::fuzz::QuietLogs();
    const std::string d = ScratchDir::Get().MakeDir("folder");
    for (const char* f : {"folder/img1.png", "folder/img2.png", "folder/img10.png"}) {
      ScratchDir::Get().Touch(f);
    }
    return d;
  }();
  if (size < 1) return 0;
  static const char* const kUnits[4] = {"s", "ms", "us", "ns"};
  mbslam::FolderOptions options;
  options.timestamps_unit = kUnits[data[0] % 4];
  options.timestamps_file = ScratchDir::Get().Write("timestamps.txt", data + 1, size - 1);
  mbslam::ImageIndex index;
  if (mbslam::IndexImageFolder(dir, options, &index).ok()) mbslam::fuzz::CheckIndex(index);
  return 0;
}
