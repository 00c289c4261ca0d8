#include "drivers/camera/dc1394_modes.h"

#include <opencv2/imgproc.hpp>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

namespace mbslam {
namespace {

struct ModeName {
  dc1394video_mode_t mode;
  const char* name;
};

const ModeName kModes[] = {
    {DC1394_VIDEO_MODE_160x120_YUV444, "160x120_YUV444"},
    {DC1394_VIDEO_MODE_320x240_YUV422, "320x240_YUV422"},
    {DC1394_VIDEO_MODE_640x480_YUV411, "640x480_YUV411"},
    {DC1394_VIDEO_MODE_640x480_YUV422, "640x480_YUV422"},
    {DC1394_VIDEO_MODE_640x480_RGB8, "640x480_RGB8"},
    {DC1394_VIDEO_MODE_640x480_MONO8, "640x480_MONO8"},
    {DC1394_VIDEO_MODE_640x480_MONO16, "640x480_MONO16"},
    {DC1394_VIDEO_MODE_800x600_YUV422, "800x600_YUV422"},
    {DC1394_VIDEO_MODE_800x600_RGB8, "800x600_RGB8"},
    {DC1394_VIDEO_MODE_800x600_MONO8, "800x600_MONO8"},
    {DC1394_VIDEO_MODE_1024x768_YUV422, "1024x768_YUV422"},
    {DC1394_VIDEO_MODE_1024x768_RGB8, "1024x768_RGB8"},
    {DC1394_VIDEO_MODE_1024x768_MONO8, "1024x768_MONO8"},
    {DC1394_VIDEO_MODE_800x600_MONO16, "800x600_MONO16"},
    {DC1394_VIDEO_MODE_1024x768_MONO16, "1024x768_MONO16"},
    {DC1394_VIDEO_MODE_1280x960_YUV422, "1280x960_YUV422"},
    {DC1394_VIDEO_MODE_1280x960_RGB8, "1280x960_RGB8"},
    {DC1394_VIDEO_MODE_1280x960_MONO8, "1280x960_MONO8"},
    {DC1394_VIDEO_MODE_1600x1200_YUV422, "1600x1200_YUV422"},
    {DC1394_VIDEO_MODE_1600x1200_RGB8, "1600x1200_RGB8"},
    {DC1394_VIDEO_MODE_1600x1200_MONO8, "1600x1200_MONO8"},
    {DC1394_VIDEO_MODE_1280x960_MONO16, "1280x960_MONO16"},
    {DC1394_VIDEO_MODE_1600x1200_MONO16, "1600x1200_MONO16"},
    {DC1394_VIDEO_MODE_EXIF, "EXIF"},
    {DC1394_VIDEO_MODE_FORMAT7_0, "FORMAT7_0"},
    {DC1394_VIDEO_MODE_FORMAT7_1, "FORMAT7_1"},
    {DC1394_VIDEO_MODE_FORMAT7_2, "FORMAT7_2"},
    {DC1394_VIDEO_MODE_FORMAT7_3, "FORMAT7_3"},
    {DC1394_VIDEO_MODE_FORMAT7_4, "FORMAT7_4"},
    {DC1394_VIDEO_MODE_FORMAT7_5, "FORMAT7_5"},
    {DC1394_VIDEO_MODE_FORMAT7_6, "FORMAT7_6"},
    {DC1394_VIDEO_MODE_FORMAT7_7, "FORMAT7_7"},
};

struct CodingName {
  dc1394color_coding_t coding;
  const char* name;
};

const CodingName kCodings[] = {
    {DC1394_COLOR_CODING_MONO8, "MONO8"},   {DC1394_COLOR_CODING_YUV411, "YUV411"},
    {DC1394_COLOR_CODING_YUV422, "YUV422"}, {DC1394_COLOR_CODING_YUV444, "YUV444"},
    {DC1394_COLOR_CODING_RGB8, "RGB8"},     {DC1394_COLOR_CODING_MONO16, "MONO16"},
    {DC1394_COLOR_CODING_RGB16, "RGB16"},   {DC1394_COLOR_CODING_MONO16S, "MONO16S"},
    {DC1394_COLOR_CODING_RGB16S, "RGB16S"}, {DC1394_COLOR_CODING_RAW8, "RAW8"},
    {DC1394_COLOR_CODING_RAW16, "RAW16"},
};

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// OpenCV names Bayer patterns by the second row's first two pixels.
Status BayerCode(const std::string& pattern, int* code) {
  if (pattern == "RGGB") {
    *code = cv::COLOR_BayerBG2BGR;
  } else if (pattern == "GBRG") {
    *code = cv::COLOR_BayerGR2BGR;
  } else if (pattern == "GRBG") {
    *code = cv::COLOR_BayerGB2BGR;
  } else if (pattern == "BGGR") {
    *code = cv::COLOR_BayerRG2BGR;
  } else {
    return Status::Error("unknown Bayer pattern '" + pattern + "'");
  }
  return Status::Ok();
}

std::string FilterName(dc1394color_filter_t filter) {
  switch (filter) {
    case DC1394_COLOR_FILTER_RGGB: return "RGGB";
    case DC1394_COLOR_FILTER_GBRG: return "GBRG";
    case DC1394_COLOR_FILTER_GRBG: return "GRBG";
    case DC1394_COLOR_FILTER_BGGR: return "BGGR";
  }
  return "none";
}

// 16-bit samples (big-endian unless little_endian) to 8 bits keeping the top
// `depth` significant bits.
cv::Mat SixteenToEight(const uint8_t* data, int rows, int cols_samples, size_t stride,
                       bool little_endian, uint32_t depth) {
  cv::Mat out(rows, cols_samples, CV_8UC1);
  const int shift = depth > 8 && depth <= 16 ? static_cast<int>(depth) - 8 : 8;
  for (int r = 0; r < rows; ++r) {
    const uint8_t* row = data + stride * static_cast<size_t>(r);
    uint8_t* dst = out.ptr<uint8_t>(r);
    for (int c = 0; c < cols_samples; ++c) {
      const uint8_t b0 = row[2 * c];
      const uint8_t b1 = row[2 * c + 1];
      const unsigned v = little_endian ? (b0 | (b1 << 8)) : ((b0 << 8) | b1);
      dst[c] = static_cast<uint8_t>(std::min(255u, v >> shift));
    }
  }
  return out;
}

}  // namespace

Status ParseDc1394VideoMode(const std::string& name, dc1394video_mode_t* mode) {
  const std::string upper = Upper(name);
  for (const ModeName& m : kModes) {
    if (upper == Upper(m.name)) {
      *mode = m.mode;
      return Status::Ok();
    }
  }
  std::string known;
  for (const ModeName& m : kModes) known += std::string(known.empty() ? "" : " ") + m.name;
  return Status::Error("unknown IEEE 1394 video mode '" + name + "' (known: " + known + ")");
}

std::string Dc1394VideoModeName(dc1394video_mode_t mode) {
  for (const ModeName& m : kModes) {
    if (m.mode == mode) return m.name;
  }
  return "mode" + std::to_string(static_cast<int>(mode));
}

bool IsDc1394Format7(dc1394video_mode_t mode) {
  return mode >= DC1394_VIDEO_MODE_FORMAT7_MIN && mode <= DC1394_VIDEO_MODE_FORMAT7_MAX;
}

Status ParseDc1394Framerate(double hz, dc1394framerate_t* rate) {
  for (int r = DC1394_FRAMERATE_MIN; r <= DC1394_FRAMERATE_MAX; ++r) {
    const auto fr = static_cast<dc1394framerate_t>(r);
    if (std::abs(Dc1394FramerateHz(fr) - hz) < 1e-3) {
      *rate = fr;
      return Status::Ok();
    }
  }
  char text[64];
  std::snprintf(text, sizeof(text), "%g", hz);
  return Status::Error(std::string("IEEE 1394 frame rate ") + text +
                       " Hz is not a standard rate (1.875 3.75 7.5 15 30 60 120 240)");
}

double Dc1394FramerateHz(dc1394framerate_t rate) {
  const int k = static_cast<int>(rate) - static_cast<int>(DC1394_FRAMERATE_1_875);
  return 1.875 * std::pow(2.0, k);
}

Status ParseDc1394IsoSpeed(int mbps, dc1394speed_t* speed) {
  switch (mbps) {
    case 100: *speed = DC1394_ISO_SPEED_100; return Status::Ok();
    case 200: *speed = DC1394_ISO_SPEED_200; return Status::Ok();
    case 400: *speed = DC1394_ISO_SPEED_400; return Status::Ok();
    case 800: *speed = DC1394_ISO_SPEED_800; return Status::Ok();
    case 1600: *speed = DC1394_ISO_SPEED_1600; return Status::Ok();
    case 3200: *speed = DC1394_ISO_SPEED_3200; return Status::Ok();
    default: break;
  }
  return Status::Error("ISO speed " + std::to_string(mbps) + " Mb/s is not one of 100 200 400 800 1600 3200");
}

Status ParseDc1394ColorCoding(const std::string& name, dc1394color_coding_t* coding) {
  const std::string upper = Upper(name);
  for (const CodingName& c : kCodings) {
    if (upper == c.name) {
      *coding = c.coding;
      return Status::Ok();
    }
  }
  return Status::Error("unknown IEEE 1394 colour coding '" + name + "'");
}

std::string Dc1394ColorCodingName(dc1394color_coding_t coding) {
  for (const CodingName& c : kCodings) {
    if (c.coding == coding) return c.name;
  }
  return "coding" + std::to_string(static_cast<int>(coding));
}

Status ParseDc1394Guid(const std::string& text, uint64_t* guid) {
  if (text.empty()) return Status::Error("empty GUID");
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text.c_str(), &end, 0);
  if (*end != '\0' || errno != 0 || text[0] == '-') {
    return Status::Error("'" + text + "' is not a GUID (hex like 0x00b09d0100a1b2c3)");
  }
  *guid = static_cast<uint64_t>(v);
  return Status::Ok();
}

std::string FormatDc1394Guid(uint64_t guid) {
  char text[32];
  std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(guid));
  return text;
}

Status ConvertDc1394Frame(const dc1394video_frame_t& frame, const std::string& bayer_pattern,
                          cv::Mat* image) {
  const int w = static_cast<int>(frame.size[0]);
  const int h = static_cast<int>(frame.size[1]);
  if (frame.image == nullptr || w <= 0 || h <= 0) return Status::Error("empty IEEE 1394 frame");
  uint8_t* data = frame.image;
  auto stride_or = [&](size_t bytes_per_pixel) {
    return frame.stride > 0 ? static_cast<size_t>(frame.stride) : bytes_per_pixel * static_cast<size_t>(w);
  };
  auto check_bytes = [&](size_t stride, size_t row_bytes) -> Status {
    if (stride < row_bytes) return Status::Error("IEEE 1394 frame stride smaller than a row");
    if (frame.image_bytes > 0 && stride * static_cast<size_t>(h - 1) + row_bytes > frame.image_bytes) {
      return Status::Error("IEEE 1394 frame smaller than width x height");
    }
    return Status::Ok();
  };
  std::string pattern = bayer_pattern;
  switch (frame.color_coding) {
    case DC1394_COLOR_CODING_RAW8:
      if (pattern == "none") pattern = FilterName(frame.color_filter);
      [[fallthrough]];
    case DC1394_COLOR_CODING_MONO8: {
      const size_t stride = stride_or(1);
      MBSLAM_RETURN_IF_ERROR(check_bytes(stride, static_cast<size_t>(w)));
      const cv::Mat view(h, w, CV_8UC1, data, stride);
      if (pattern != "none") {
        int code = 0;
        MBSLAM_RETURN_IF_ERROR(BayerCode(pattern, &code));
        cv::cvtColor(view, *image, code);
      } else {
        *image = view.clone();
      }
      return Status::Ok();
    }
    case DC1394_COLOR_CODING_MONO16:
    case DC1394_COLOR_CODING_RAW16: {
      const size_t stride = stride_or(2);
      MBSLAM_RETURN_IF_ERROR(check_bytes(stride, 2 * static_cast<size_t>(w)));
      cv::Mat eight = SixteenToEight(data, h, w, stride, frame.little_endian == DC1394_TRUE,
                                     frame.data_depth);
      if (frame.color_coding == DC1394_COLOR_CODING_RAW16 && pattern == "none") {
        pattern = FilterName(frame.color_filter);
      }
      if (pattern != "none") {
        int code = 0;
        MBSLAM_RETURN_IF_ERROR(BayerCode(pattern, &code));
        cv::cvtColor(eight, *image, code);
      } else {
        *image = eight;
      }
      return Status::Ok();
    }
    case DC1394_COLOR_CODING_RGB8: {
      const size_t stride = stride_or(3);
      MBSLAM_RETURN_IF_ERROR(check_bytes(stride, 3 * static_cast<size_t>(w)));
      cv::cvtColor(cv::Mat(h, w, CV_8UC3, data, stride), *image, cv::COLOR_RGB2BGR);
      return Status::Ok();
    }
    case DC1394_COLOR_CODING_RGB16: {
      const size_t stride = stride_or(6);
      MBSLAM_RETURN_IF_ERROR(check_bytes(stride, 6 * static_cast<size_t>(w)));
      cv::Mat rgb = SixteenToEight(data, h, 3 * w, stride, frame.little_endian == DC1394_TRUE,
                                   frame.data_depth);
      cv::cvtColor(rgb.reshape(3, h), *image, cv::COLOR_RGB2BGR);
      return Status::Ok();
    }
    case DC1394_COLOR_CODING_YUV411:
    case DC1394_COLOR_CODING_YUV422:
    case DC1394_COLOR_CODING_YUV444: {
      // libdc1394's conversion: IIDC YUV is full range (Y 0-255), unlike OpenCV's
      // video-range YUV conversions. Its buffers are packed (no row padding).
      const size_t pixels = static_cast<size_t>(w) * static_cast<size_t>(h);
      const size_t bytes = frame.color_coding == DC1394_COLOR_CODING_YUV411   ? pixels * 3 / 2
                           : frame.color_coding == DC1394_COLOR_CODING_YUV422 ? pixels * 2
                                                                              : pixels * 3;
      if (frame.image_bytes > 0 && frame.image_bytes < bytes) {
        return Status::Error("IEEE 1394 frame smaller than width x height");
      }
      cv::Mat rgb(h, w, CV_8UC3);
      const uint32_t order =
          frame.yuv_byte_order == DC1394_BYTE_ORDER_YUYV ? DC1394_BYTE_ORDER_YUYV : DC1394_BYTE_ORDER_UYVY;
      if (dc1394_convert_to_RGB8(data, rgb.data, static_cast<uint32_t>(w), static_cast<uint32_t>(h),
                                 order, frame.color_coding, 8) != DC1394_SUCCESS) {
        return Status::Error("libdc1394 could not convert " +
                             Dc1394ColorCodingName(frame.color_coding));
      }
      cv::cvtColor(rgb, *image, cv::COLOR_RGB2BGR);
      return Status::Ok();
    }
    default:
      break;
  }
  return Status::Error("unsupported IEEE 1394 colour coding " +
                       Dc1394ColorCodingName(frame.color_coding));
}

}  // namespace mbslam
