#ifndef MBSLAM_DRIVERS_CAMERA_IMAGE_CODEC_H_
#define MBSLAM_DRIVERS_CAMERA_IMAGE_CODEC_H_

// Image files and buffers to the 8-bit gray / BGR images camera_driver publishes.

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

#include "common/util/status.h"

namespace mbslam {

enum class ImageFileType { kUnknown, kJpeg, kPng };

// Sniffs the magic bytes of a JPEG or PNG file.
ImageFileType DetectImageFileType(const std::string& bytes);

// Converts any decoded image to 8-bit gray (1 channel) or BGR (3 channels): 16-bit is
// scaled to 8 bits (>> 8), alpha is dropped. `*changed` tells whether pixels differ
// from the input's (so the original file bytes no longer describe them).
Status NormalizeImage(const cv::Mat& in, cv::Mat* out, bool* changed);

// Decodes file bytes (any format OpenCV reads) and normalises them. `*unchanged_file`
// is true when `bytes` is a JPEG / PNG whose pixels are exactly `*image`.
Status DecodeImageBytes(const std::string& bytes, cv::Mat* image, ImageFileType* type,
                        bool* unchanged_file);

// Applies a colour policy: "keep", "gray" (BGR -> gray) or "bgr" (gray -> 3 equal
// channels). `*changed` as above.
Status ApplyColorPolicy(const cv::Mat& in, const std::string& color, cv::Mat* out, bool* changed);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_CAMERA_IMAGE_CODEC_H_
