// Fuzz target: the perception service's SNAPSHOT_REQUEST handler
// (InputAdapter::HandleSnapshotRequest). Input: one snapshot_request_t encoding.
//
// Properties: nothing throws or crashes; a request handed on carries a path prefix
// without NUL bytes (it becomes a file name).

#include <string>

#include "test/fuzz/input_adapter_fixture.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  mbslam::fuzz::InputAdapterFixture f;
  f.adapter->set_snapshot_callback([](const std::string& prefix, int) {
    if (prefix.find('\0') != std::string::npos) {
      mbslam::fuzz::Fail("snapshot path prefix with a NUL byte handed on");
    }
  });
  f.adapter->HandleSnapshotRequest(data, size);
  return 0;
}
