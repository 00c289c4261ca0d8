// Fuzz target: the bounded LCM decode every subscriber uses (common/lcm/wire_check.h),
// for every message type. Input: one tag byte selecting the type (lcm_types.h), then
// the encoded message (fingerprint first).
//
// Properties: DecodeLcmMessage never throws or over-allocates; what it accepts,
// lcm-gen's encoder writes back byte for byte (the schema walk and the generated
// decoder agree on where every field is).

#include <cstring>
#include <vector>

#include "common/lcm/wire_check.h"
#include "test/fuzz/fuzz_util.h"
#include "test/fuzz/lcm_types.h"

namespace {

template <typename Msg>
void DecodeAs(const uint8_t* data, size_t size) {
  Msg msg{};
  if (!mbslam::DecodeLcmMessage(data, size, &msg).ok()) return;
  const int encoded_size = msg.getEncodedSize();
  if (encoded_size != static_cast<int>(size)) {
    mbslam::fuzz::Fail("accepted message re-encodes to a different size");
  }
  std::vector<uint8_t> again(size);
  if (msg.encode(again.data(), 0, encoded_size) != encoded_size ||
      (size > 0 && std::memcmp(again.data(), data, size) != 0)) {
    mbslam::fuzz::Fail("accepted message re-encodes to different bytes");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const int index = data[0] % mbslam::fuzz::kNumLcmTypes;
  int i = 0;
#define MBSLAM_FUZZ_DECODE(t)                           \
  if (i++ == index) DecodeAs<mbslam::t>(data + 1, size - 1);
  MBSLAM_FOR_EACH_LCM_TYPE(MBSLAM_FUZZ_DECODE)
#undef MBSLAM_FUZZ_DECODE
  return 0;
}
