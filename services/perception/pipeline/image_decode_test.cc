#include "services/perception/pipeline/image_decode.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace mbslam {
namespace {

cv::Mat Pattern(int w, int h) {
  cv::Mat m(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(x * 3, y * 5, (x ^ y) & 255);
  }
  return m;
}

RawImage Compressed(const cv::Mat& m, const std::string& ext, ImageEncoding e) {
  RawImage raw;
  cv::imencode(ext, m, raw.bytes);
  raw.encoding = e;
  raw.width = m.cols;
  raw.height = m.rows;
  return raw;
}

TEST(ImageDecode, RawGrayWithStride) {
  RawImage raw;
  raw.width = 3;
  raw.height = 2;
  raw.row_stride = 4;
  raw.encoding = ImageEncoding::kGray8;
  raw.bytes = {1, 2, 3, 99, 4, 5, 6};
  ASSERT_TRUE(ValidateRawImage(raw, 100).ok());
  ImageFrame f;
  ASSERT_TRUE(DecodeImage(raw, false, &f).ok());
  EXPECT_EQ(f.gray.at<uint8_t>(1, 2), 6);
  raw.bytes.pop_back();
  EXPECT_FALSE(ValidateRawImage(raw, 100).ok());
  raw.row_stride = 2;
  EXPECT_FALSE(ValidateRawImage(raw, 100).ok());
}

TEST(ImageDecode, RgbAndBgrGiveTheSameGray) {
  const cv::Mat bgr = Pattern(16, 8);
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  RawImage a, b;
  for (RawImage* r : {&a, &b}) {
    r->width = 16;
    r->height = 8;
    r->row_stride = 48;
  }
  a.encoding = ImageEncoding::kBgr8;
  a.bytes.assign(bgr.data, bgr.data + bgr.total() * 3);
  b.encoding = ImageEncoding::kRgb8;
  b.bytes.assign(rgb.data, rgb.data + rgb.total() * 3);
  ImageFrame fa, fb;
  ASSERT_TRUE(DecodeImage(a, true, &fa).ok());
  ASSERT_TRUE(DecodeImage(b, true, &fb).ok());
  EXPECT_EQ(cv::norm(fa.gray, fb.gray, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(fa.color, fb.color, cv::NORM_INF), 0.0);
}

TEST(ImageDecode, PngIsLosslessAndJpegDecodes) {
  const cv::Mat bgr = Pattern(40, 30);
  RawImage png = Compressed(bgr, ".png", ImageEncoding::kPng);
  ASSERT_TRUE(ValidateRawImage(png, 100).ok());
  ImageFrame f;
  ASSERT_TRUE(DecodeImage(png, true, &f).ok());
  EXPECT_EQ(cv::norm(f.color, bgr, cv::NORM_INF), 0.0);
  RawImage jpg = Compressed(bgr, ".jpg", ImageEncoding::kJpeg);
  ASSERT_TRUE(ValidateRawImage(jpg, 100).ok()) << ValidateRawImage(jpg, 100).message();
  ASSERT_TRUE(DecodeImage(jpg, false, &f).ok());
  EXPECT_EQ(f.gray.cols, 40);
}

TEST(ImageDecode, LyingHeaderAndGarbageAreRejected) {
  RawImage jpg = Compressed(Pattern(40, 30), ".jpg", ImageEncoding::kJpeg);
  jpg.width = 4000;
  EXPECT_FALSE(ValidateRawImage(jpg, 8192).ok());
  RawImage garbage;
  garbage.encoding = ImageEncoding::kPng;
  garbage.width = 10;
  garbage.height = 10;
  garbage.bytes.assign(100, 0xAB);
  EXPECT_FALSE(ValidateRawImage(garbage, 100).ok());
  ImageFrame f;
  EXPECT_FALSE(DecodeImage(garbage, false, &f).ok());
  RawImage truncated = Compressed(Pattern(40, 30), ".png", ImageEncoding::kPng);
  truncated.bytes.resize(truncated.bytes.size() / 2);
  EXPECT_FALSE(DecodeImage(truncated, false, &f).ok());
  RawImage huge;
  huge.width = 100000;
  huge.height = 2;
  EXPECT_FALSE(ValidateRawImage(huge, 8192).ok());
}

// Regression (fuzzing, issue 9): a raw image whose data holds more than height full
// rows disagrees with its geometry and is dropped like one holding too few; a header
// announcing gigabytes is rejected from the sizes alone, before any allocation.
TEST(ImageDecode, RawDataMustMatchTheGeometry) {
  RawImage raw;
  raw.width = 3;
  raw.height = 2;
  raw.row_stride = 4;
  raw.encoding = ImageEncoding::kGray8;
  raw.bytes.assign(8, 7);  // two full rows
  EXPECT_TRUE(ValidateRawImage(raw, 100).ok());
  raw.bytes.push_back(7);
  EXPECT_FALSE(ValidateRawImage(raw, 100).ok());
  raw.encoding = ImageEncoding::kRgb8;
  raw.row_stride = 9;
  raw.bytes.assign(18, 1);
  EXPECT_TRUE(ValidateRawImage(raw, 100).ok());
  raw.bytes.assign(54, 1);  // three times the pixels of 3x2 RGB
  EXPECT_FALSE(ValidateRawImage(raw, 100).ok());

  RawImage huge;  // 65535 x 65535 x 3 bytes = 12 GB announced, 16 bytes sent
  huge.width = 65535;
  huge.height = 65535;
  huge.row_stride = 3 * 65535;
  huge.encoding = ImageEncoding::kBgr8;
  huge.bytes.assign(16, 0);
  EXPECT_FALSE(ValidateRawImage(huge, 1 << 20).ok());
}

}  // namespace
}  // namespace mbslam
