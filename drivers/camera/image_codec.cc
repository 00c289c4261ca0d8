#include "drivers/camera/image_codec.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <vector>

namespace mbslam {

ImageFileType DetectImageFileType(const std::string& bytes) {
  if (bytes.size() >= 3 && static_cast<uint8_t>(bytes[0]) == 0xFF &&
      static_cast<uint8_t>(bytes[1]) == 0xD8 && static_cast<uint8_t>(bytes[2]) == 0xFF) {
    return ImageFileType::kJpeg;
  }
  static const char kPngMagic[] = "\x89PNG\r\n\x1a\n";
  if (bytes.size() >= 8 && bytes.compare(0, 8, kPngMagic, 8) == 0) return ImageFileType::kPng;
  return ImageFileType::kUnknown;
}

Status NormalizeImage(const cv::Mat& in, cv::Mat* out, bool* changed) {
  *changed = false;
  if (in.empty()) return Status::Error("empty image");
  cv::Mat img = in;
  if (img.depth() == CV_16U) {
    img.convertTo(img, CV_8U, 1.0 / 256.0);
    *changed = true;
  } else if (img.depth() != CV_8U) {
    return Status::Error("unsupported pixel depth (only 8 and 16 bit)");
  }
  switch (img.channels()) {
    case 1:
    case 3:
      break;
    case 2: {  // gray + alpha
      std::vector<cv::Mat> planes;
      cv::split(img, planes);
      img = planes[0];
      *changed = true;
      break;
    }
    case 4:
      cv::cvtColor(img, img, cv::COLOR_BGRA2BGR);
      *changed = true;
      break;
    default:
      return Status::Error("unsupported number of channels: " + std::to_string(img.channels()));
  }
  *out = img.isContinuous() ? img : img.clone();
  return Status::Ok();
}

Status DecodeImageBytes(const std::string& bytes, cv::Mat* image, ImageFileType* type,
                        bool* unchanged_file) {
  *type = DetectImageFileType(bytes);
  *unchanged_file = false;
  if (bytes.empty()) return Status::Error("empty file");
  cv::Mat decoded;
  try {
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                         const_cast<char*>(bytes.data()));
    decoded = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return Status::Error(std::string("decoder failed: ") + e.what());
  }
  if (decoded.empty()) return Status::Error("not a decodable image (corrupt or unknown format)");
  bool changed = false;
  MBSLAM_RETURN_IF_ERROR(NormalizeImage(decoded, image, &changed));
  *unchanged_file = !changed && *type != ImageFileType::kUnknown;
  return Status::Ok();
}

Status ApplyColorPolicy(const cv::Mat& in, const std::string& color, cv::Mat* out,
                        bool* changed) {
  *changed = false;
  if (color == "keep") {
    *out = in;
  } else if (color == "gray") {
    if (in.channels() == 3) {
      cv::cvtColor(in, *out, cv::COLOR_BGR2GRAY);
      *changed = true;
    } else {
      *out = in;
    }
  } else if (color == "bgr") {
    if (in.channels() == 1) {
      cv::cvtColor(in, *out, cv::COLOR_GRAY2BGR);
      *changed = true;
    } else {
      *out = in;
    }
  } else {
    return Status::Error("unknown colour policy '" + color + "'");
  }
  return Status::Ok();
}

}  // namespace mbslam
