#include "services/perception/pipeline/image_decode.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace mbslam {
namespace {

int Channels(ImageEncoding e) {
  switch (e) {
    case ImageEncoding::kGray8: return 1;
    case ImageEncoding::kRgb8: case ImageEncoding::kBgr8: return 3;
    default: return 0;
  }
}

// Reads the frame size from a JPEG SOF or PNG IHDR header without decoding, so a
// lying header is caught before the decoder allocates for it.
bool CompressedSize(const RawImage& raw, int* width, int* height) {
  const std::vector<uint8_t>& b = raw.bytes;
  if (raw.encoding == ImageEncoding::kPng) {
    if (b.size() < 24 || b[0] != 0x89 || b[1] != 'P' || b[2] != 'N' || b[3] != 'G') return false;
    *width = (b[16] << 24) | (b[17] << 16) | (b[18] << 8) | b[19];
    *height = (b[20] << 24) | (b[21] << 16) | (b[22] << 8) | b[23];
    return true;
  }
  if (raw.encoding == ImageEncoding::kJpeg) {
    if (b.size() < 4 || b[0] != 0xFF || b[1] != 0xD8) return false;
    size_t pos = 2;
    while (pos + 9 < b.size()) {
      if (b[pos] != 0xFF) return false;
      const uint8_t marker = b[pos + 1];
      if (marker == 0xFF) {  // fill byte
        ++pos;
        continue;
      }
      const size_t len = (static_cast<size_t>(b[pos + 2]) << 8) | b[pos + 3];
      const bool sof = (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                        marker != 0xCC);
      if (sof) {
        *height = (b[pos + 5] << 8) | b[pos + 6];
        *width = (b[pos + 7] << 8) | b[pos + 8];
        return true;
      }
      if (len < 2) return false;
      pos += 2 + len;
    }
  }
  return false;
}

}  // namespace

Status ValidateRawImage(const RawImage& raw, int max_dimension) {
  if (raw.width <= 0 || raw.height <= 0 || raw.width > max_dimension ||
      raw.height > max_dimension) {
    return Status::Error("image size " + std::to_string(raw.width) + "x" +
                         std::to_string(raw.height) + " out of range");
  }
  const int channels = Channels(raw.encoding);
  if (channels > 0) {
    const int64_t min_stride = static_cast<int64_t>(raw.width) * channels;
    if (raw.row_stride < min_stride) {
      return Status::Error("row_stride " + std::to_string(raw.row_stride) + " < width * channels");
    }
    // The last row may stop at width * channels; more than height full rows is a
    // message whose geometry disagrees with its data.
    const int64_t needed = static_cast<int64_t>(raw.row_stride) * (raw.height - 1) + min_stride;
    const int64_t full = static_cast<int64_t>(raw.row_stride) * raw.height;
    const int64_t have = static_cast<int64_t>(raw.bytes.size());
    if (have < needed || have > full) {
      return Status::Error("image has " + std::to_string(have) + " bytes, " +
                           std::to_string(raw.width) + "x" + std::to_string(raw.height) +
                           " with row_stride " + std::to_string(raw.row_stride) + " needs " +
                           (needed == full ? std::to_string(needed)
                                           : std::to_string(needed) + ".." + std::to_string(full)));
    }
    return Status::Ok();
  }
  int w = 0, h = 0;
  if (!CompressedSize(raw, &w, &h)) return Status::Error("compressed image header unreadable");
  if (w != raw.width || h != raw.height) {
    return Status::Error("compressed image is " + std::to_string(w) + "x" + std::to_string(h) +
                         ", message says " + std::to_string(raw.width) + "x" +
                         std::to_string(raw.height));
  }
  return Status::Ok();
}

Status DecodeImage(const RawImage& raw, bool keep_color, ImageFrame* frame) {
  frame->utime = raw.utime;
  frame->seq = raw.seq;
  frame->receive_wall_utime = raw.receive_wall_utime;
  frame->color.release();
  const int channels = Channels(raw.encoding);
  if (channels > 0) {
    const cv::Mat view(raw.height, raw.width, channels == 1 ? CV_8UC1 : CV_8UC3,
                       const_cast<uint8_t*>(raw.bytes.data()), static_cast<size_t>(raw.row_stride));
    if (raw.encoding == ImageEncoding::kGray8) {
      frame->gray = view.clone();
    } else {
      const int to_gray = raw.encoding == ImageEncoding::kRgb8 ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY;
      cv::cvtColor(view, frame->gray, to_gray);
      if (keep_color) {
        if (raw.encoding == ImageEncoding::kRgb8) cv::cvtColor(view, frame->color, cv::COLOR_RGB2BGR);
        else frame->color = view.clone();
      }
    }
    return Status::Ok();
  }
  cv::Mat decoded;
  try {
    const cv::Mat buf(1, static_cast<int>(raw.bytes.size()), CV_8UC1,
                      const_cast<uint8_t*>(raw.bytes.data()));
    decoded = cv::imdecode(buf, keep_color ? cv::IMREAD_COLOR : cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    return Status::Error(std::string("image decoder failed: ") + e.what());
  }
  if (decoded.empty()) return Status::Error("image decoder failed");
  if (decoded.cols != raw.width || decoded.rows != raw.height) {
    return Status::Error("decoded image size differs from the message");
  }
  if (decoded.channels() == 3) {
    frame->color = decoded;
    cv::cvtColor(decoded, frame->gray, cv::COLOR_BGR2GRAY);
  } else {
    frame->gray = decoded;
  }
  return Status::Ok();
}

}  // namespace mbslam
