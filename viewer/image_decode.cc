#include "viewer/image_decode.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <string>
#include <vector>

namespace mbslam {
namespace viewer {
namespace {

uint32_t BigEndian(const uint8_t* p, int bytes) {
  uint32_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

// The pixel size a PNG or JPEG file announces in its header, without decoding it.
bool PeekCompressedSize(const std::vector<uint8_t>& d, int* width, int* height) {
  static const uint8_t kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (d.size() >= 24 && std::equal(kPngSignature, kPngSignature + 8, d.begin())) {
    *width = static_cast<int>(std::min<uint32_t>(BigEndian(&d[16], 4), 1u << 30));
    *height = static_cast<int>(std::min<uint32_t>(BigEndian(&d[20], 4), 1u << 30));
    return true;
  }
  if (d.size() >= 4 && d[0] == 0xFF && d[1] == 0xD8) {  // JPEG: walk the markers to a SOFn
    size_t i = 2;
    while (i + 4 <= d.size()) {
      if (d[i] != 0xFF) return false;
      const uint8_t marker = d[i + 1];
      if (marker == 0xFF) {  // fill byte
        ++i;
        continue;
      }
      const size_t length = BigEndian(&d[i + 2], 2);
      const bool sof =
          marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
      if (sof) {
        if (i + 9 > d.size()) return false;
        *height = static_cast<int>(BigEndian(&d[i + 5], 2));
        *width = static_cast<int>(BigEndian(&d[i + 7], 2));
        return true;
      }
      if (length < 2) return false;
      i += 2 + length;
    }
  }
  return false;
}

}  // namespace

Status DecodeToBgr(const EncodedImage& image, int max_dimension, cv::Mat* bgr) {
  const std::string size_text = std::to_string(image.width) + "x" + std::to_string(image.height);
  const bool compressed =
      image.encoding == ImageEncoding::kJpeg || image.encoding == ImageEncoding::kPng;
  if (compressed) {
    if (image.data.empty()) return Status::Error("empty compressed image");
    if (image.width > max_dimension || image.height > max_dimension) {
      return Status::Error("image of " + size_text + " px is larger than allowed");
    }
    // The header's size is checked before decoding, so a small file cannot make the
    // decoder allocate a huge image.
    int file_width = 0, file_height = 0;
    if (!PeekCompressedSize(image.data, &file_width, &file_height)) {
      return Status::Error("not a PNG or JPEG file");
    }
    if (file_width <= 0 || file_height <= 0 || file_width > max_dimension ||
        file_height > max_dimension) {
      return Status::Error("compressed image of " + std::to_string(file_width) + "x" +
                           std::to_string(file_height) + " px is larger than allowed");
    }
    cv::Mat decoded;
    try {
      const cv::Mat bytes(1, static_cast<int>(image.data.size()), CV_8UC1,
                          const_cast<uint8_t*>(image.data.data()));
      decoded = cv::imdecode(bytes, cv::IMREAD_COLOR);
    } catch (const cv::Exception& e) {
      return Status::Error(std::string("image decode threw: ") + e.what());
    }
    if (decoded.empty()) return Status::Error("compressed image does not decode");
    if ((image.width > 0 && decoded.cols != image.width) ||
        (image.height > 0 && decoded.rows != image.height)) {
      return Status::Error("compressed image decodes to " + std::to_string(decoded.cols) + "x" +
                           std::to_string(decoded.rows) + " px, message says " + size_text);
    }
    *bgr = decoded;
    return Status::Ok();
  }
  int channels = 0;
  switch (image.encoding) {
    case ImageEncoding::kGray8:
      channels = 1;
      break;
    case ImageEncoding::kRgb8:
    case ImageEncoding::kBgr8:
      channels = 3;
      break;
    default:
      return Status::Error("unknown image encoding " +
                           std::to_string(static_cast<int>(image.encoding)));
  }
  if (image.width <= 0 || image.height <= 0 || image.width > max_dimension ||
      image.height > max_dimension) {
    return Status::Error("bad image size " + size_text + " px");
  }
  const int64_t row_bytes = static_cast<int64_t>(image.width) * channels;
  if (image.row_stride < row_bytes) {
    return Status::Error("row stride " + std::to_string(image.row_stride) + " < " +
                         std::to_string(row_bytes) + " bytes for " + size_text);
  }
  const int64_t needed = static_cast<int64_t>(image.row_stride) * (image.height - 1) + row_bytes;
  if (static_cast<int64_t>(image.data.size()) < needed) {
    return Status::Error("image of " + size_text + " needs " + std::to_string(needed) +
                         " bytes, has " + std::to_string(image.data.size()));
  }
  const cv::Mat view(image.height, image.width, channels == 1 ? CV_8UC1 : CV_8UC3,
                     const_cast<uint8_t*>(image.data.data()),
                     static_cast<size_t>(image.row_stride));
  switch (image.encoding) {
    case ImageEncoding::kGray8:
      cv::cvtColor(view, *bgr, cv::COLOR_GRAY2BGR);
      break;
    case ImageEncoding::kRgb8:
      cv::cvtColor(view, *bgr, cv::COLOR_RGB2BGR);
      break;
    default:
      *bgr = view.clone();
      break;
  }
  return Status::Ok();
}

}  // namespace viewer
}  // namespace mbslam
