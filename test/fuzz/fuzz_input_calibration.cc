// Fuzz target: the perception service's CAMERA_CALIBRATION handler
// (InputAdapter::HandleCalibration). Input: records (fuzz_util.h); tag 0 = a
// camera_calibration_t encoding, anything else = an image_t encoding, handled in order,
// so calibrations meet the images they describe.
//
// Properties: nothing throws or crashes; NaN / infinite / non-positive intrinsics never
// reach the core (the processor checks every frame's intrinsics).

#include "test/fuzz/input_adapter_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mbslam::fuzz::InputAdapterFixture f;
  for (const mbslam::fuzz::Record& r : mbslam::fuzz::SplitRecords(data, size, 8)) {
    if (r.tag % 2 == 0) {
      f.adapter->HandleCalibration(r.data, r.size);
    } else {
      f.adapter->HandleImage(r.data, r.size, /*wall_utime=*/1);
    }
  }
  return 0;
}
