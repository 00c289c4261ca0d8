// Fuzz target: the perception service's CAMERA_IMAGE handler (InputAdapter::HandleImage)
// and, for what it accepts, the pipeline's image decode (raw / JPEG / PNG). Input: one
// or more image_t encodings as records (fuzz_util.h; tag ignored), handled in order.
//
// Properties: nothing throws, crashes or allocates beyond the bounds; every image that
// reaches the core has its announced size and valid intrinsics.

#include "test/fuzz/input_adapter_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mbslam::fuzz::InputAdapterFixture f;
  for (const mbslam::fuzz::Record& r : mbslam::fuzz::SplitRecords(data, size, 8)) {
    f.adapter->HandleImage(r.data, r.size, /*wall_utime=*/1);
  }
  return 0;
}
