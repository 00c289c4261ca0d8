// Fuzz target: the odometry bridge's LCM pose input (OdometryFromPoseMessage,
// odometry_bridge --input lcm) with twists derived from consecutive poses. Input: one or
// more pose_t encodings as records (fuzz_util.h; tag ignored), handled in order.
//
// Properties: nothing throws or crashes; a sample that passes ValidateOdometrySample
// (what the bridge then publishes) is finite.

#include <optional>

#include "drivers/odometry_bridge/odometry_sample.h"
#include "test/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  std::optional<mbslam::OdometrySample> previous;
  for (const mbslam::fuzz::Record& r : mbslam::fuzz::SplitRecords(data, size, 16)) {
    mbslam::OdometrySample s;
    if (!mbslam::OdometryFromPoseMessage(r.data, r.size, previous ? &*previous : nullptr,
                                         /*derive_twist=*/true, &s)
             .ok()) {
      continue;
    }
    if (mbslam::ValidateOdometrySample(s).ok() &&
        (!s.linear_velocity.allFinite() || !s.odom_from_base.translation.allFinite())) {
      mbslam::fuzz::Fail("validated sample is not finite");
    }
    previous = s;
  }
  return 0;
}
