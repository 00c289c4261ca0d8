// Fuzz target: the trajectory readers of drivers/common/pose_files.h. Input: one byte
// choosing the reader (0 TUM "t tx ty tz qx qy qz qw", 1 KITTI 3x4 rows, 2 TartanAir
// "tx ty tz qx qy qz qw"), then the file.
//
// Properties: nothing throws or crashes; accepted poses are finite rotations, TUM
// times increase.

#include <string>
#include <vector>

#include "drivers/common/pose_files.h"
#include "test/fuzz/dataset_checks.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  if (size < 1) return 0;
  const std::string path = mbslam::fuzz::ScratchDir::Get().Write("poses.txt", data + 1, size - 1);
  switch (data[0] % 3) {
    case 0: {
      std::vector<mbslam::TimedPose> poses;
      if (!mbslam::ReadTumTrajectory(path, &poses).ok()) break;
      for (size_t i = 0; i < poses.size(); ++i) {
        mbslam::fuzz::CheckPose(poses[i].pose);
        if (i > 0 && poses[i].utime <= poses[i - 1].utime) mbslam::fuzz::Fail("TUM times do not increase");
      }
      break;
    }
    case 1:
    case 2: {
      std::vector<mbslam::Rigid3d> poses;
      const mbslam::Status s = data[0] % 3 == 1 ? mbslam::ReadKittiPoses(path, &poses)
                                                : mbslam::ReadTartanAirPoses(path, &poses);
      if (!s.ok()) break;
      for (const mbslam::Rigid3d& p : poses) mbslam::fuzz::CheckPose(p);
      break;
    }
  }
  return 0;
}
