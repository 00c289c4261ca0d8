// Fuzz target: the perception service's ODOMETRY handler (InputAdapter::HandleOdometry).
// Input: one or more odometry_t encodings as records (fuzz_util.h; tag ignored).
//
// Properties: nothing throws or crashes; only finite samples with a unit quaternion
// reach the core.

#include "test/fuzz/input_adapter_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mbslam::fuzz::InputAdapterFixture f;
  for (const mbslam::fuzz::Record& r : mbslam::fuzz::SplitRecords(data, size, 16)) {
    f.adapter->HandleOdometry(r.data, r.size);
  }
  return 0;
}
