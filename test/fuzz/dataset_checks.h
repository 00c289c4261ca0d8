#ifndef MBSLAM_TEST_FUZZ_DATASET_CHECKS_H_
#define MBSLAM_TEST_FUZZ_DATASET_CHECKS_H_

// What every dataset index must satisfy when its reader accepts the files.

#include <cmath>

#include "drivers/camera/image_list_source.h"
#include "test/fuzz/fuzz_util.h"

namespace mbslam {
namespace fuzz {

inline void CheckIndex(const ImageIndex& index) {
  for (size_t i = 0; i < index.entries.size(); ++i) {
    const ImageEntry& e = index.entries[i];
    if (e.path.empty()) Fail("index entry without a path");
    if (i > 0 && e.utime <= index.entries[i - 1].utime) Fail("index times do not increase");
    if (e.world_from_cam && (!e.world_from_cam->translation.allFinite() ||
                             !e.world_from_cam->rotation.coeffs().allFinite() ||
                             std::abs(e.world_from_cam->rotation.norm() - 1.0) > 1e-6)) {
      Fail("index truth pose is not finite / not a rotation");
    }
  }
}

inline void CheckPose(const Rigid3d& pose) {
  if (!pose.translation.allFinite() || !pose.rotation.coeffs().allFinite() ||
      std::abs(pose.rotation.norm() - 1.0) > 1e-6) {
    Fail("pose read from a file is not finite / not a rotation");
  }
}

}  // namespace fuzz
}  // namespace mbslam

#endif  // MBSLAM_TEST_FUZZ_DATASET_CHECKS_H_
