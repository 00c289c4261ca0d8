// Fuzz target: the perception pipeline's image decode (services/perception/pipeline/
// image_decode.h) as the service runs it: ValidateRawImage, then DecodeImage.
// Input: a 12-byte header, then the image bytes:
//   [0] encoding (image_t.ENCODING_*, modulo 5)  [1] keep_color (bit 0)
//   [2..3] width  [4..5] height (little-endian uint16)
//   [6..9] row_stride (little-endian int32)      [10..11] reserved
//
// Properties: nothing throws, crashes or allocates more than the announced size;
// an image that validates and decodes has the announced size (gray CV_8UC1, colour
// CV_8UC3 of the same size when present).

#include <cstring>

#include "services/perception/pipeline/image_decode.h"
#include "test/fuzz/fuzz_util.h"

namespace {
constexpr int kMaxDimension = 8192;  // PipelineOptions::max_image_dimension's default
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  if (size < 12) return 0;
  mbslam::RawImage raw;
  raw.encoding = static_cast<mbslam::ImageEncoding>(data[0] % 5);
  const bool keep_color = data[1] & 1;
  raw.width = data[2] | data[3] << 8;
  raw.height = data[4] | data[5] << 8;
  uint32_t stride = 0;
  for (int b = 0; b < 4; ++b) stride |= static_cast<uint32_t>(data[6 + b]) << (8 * b);
  std::memcpy(&raw.row_stride, &stride, sizeof(stride));
  raw.bytes.assign(data + 12, data + size);
  raw.utime = 1;

  if (!mbslam::ValidateRawImage(raw, kMaxDimension).ok()) return 0;
  mbslam::ImageFrame frame;
  if (!mbslam::DecodeImage(raw, keep_color, &frame).ok()) return 0;
  if (frame.gray.type() != CV_8UC1 || frame.gray.cols != raw.width ||
      frame.gray.rows != raw.height) {
    mbslam::fuzz::Fail("decoded gray image differs from the announced size");
  }
  if (!frame.color.empty() && (frame.color.type() != CV_8UC3 || frame.color.size() != frame.gray.size())) {
    mbslam::fuzz::Fail("decoded colour image differs from the gray one");
  }
  return 0;
}
