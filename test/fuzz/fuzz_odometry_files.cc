// Fuzz target: the odometry file readers of the odometry bridge
// (drivers/odometry_bridge/odometry_files.h). Input: one byte choosing the reader
// (0 CSV with a header or `ros2 topic echo --csv` rows, 1 TUM, 2 TUM with twists
// derived from consecutive poses), then the file.
//
// Properties: nothing throws or crashes; every sample read passes
// ValidateOdometrySample (what the bridge publishes is finite) and times increase.

#include <string>
#include <vector>

#include "drivers/odometry_bridge/odometry_files.h"
#include "test/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  if (size < 1) return 0;
  const std::string path = mbslam::fuzz::ScratchDir::Get().Write("odometry.txt", data + 1, size - 1);
  std::vector<mbslam::OdometrySample> samples;
  const int reader = data[0] % 3;
  const mbslam::Status s = reader == 0 ? mbslam::ReadOdometryCsv(path, &samples)
                                       : mbslam::ReadOdometryTum(path, reader == 2, &samples);
  if (!s.ok()) return 0;
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!mbslam::ValidateOdometrySample(samples[i]).ok()) {
      mbslam::fuzz::Fail("odometry sample read from a file does not validate");
    }
    if (i > 0 && samples[i].utime <= samples[i - 1].utime) mbslam::fuzz::Fail("odometry times do not increase");
  }
  return 0;
}
