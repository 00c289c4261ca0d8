#include "drivers/camera/image_codec.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "drivers/camera/camera_test_util.h"

namespace mbslam {
namespace {

std::string Encode(const cv::Mat& image, const std::string& ext) {
  std::vector<uint8_t> buf;
  EXPECT_TRUE(cv::imencode(ext, image, buf));
  return std::string(buf.begin(), buf.end());
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(ImageCodec, DetectsFileTypes) {
  const cv::Mat img = testing_util::MakeTestImage(8, 8, 3, 1);
  EXPECT_EQ(DetectImageFileType(Encode(img, ".png")), ImageFileType::kPng);
  EXPECT_EQ(DetectImageFileType(Encode(img, ".jpg")), ImageFileType::kJpeg);
  EXPECT_EQ(DetectImageFileType(Encode(img, ".bmp")), ImageFileType::kUnknown);
  EXPECT_EQ(DetectImageFileType(""), ImageFileType::kUnknown);
}

TEST(ImageCodec, PngDecodesBitExactAndKeepsTheFile) {
  for (int channels : {1, 3}) {
    const cv::Mat img = testing_util::MakeTestImage(33, 17, channels, channels);
    cv::Mat decoded;
    ImageFileType type;
    bool unchanged = false;
    ASSERT_TRUE(DecodeImageBytes(Encode(img, ".png"), &decoded, &type, &unchanged).ok());
    EXPECT_EQ(type, ImageFileType::kPng);
    EXPECT_TRUE(unchanged);
    EXPECT_TRUE(Identical(decoded, img));
  }
}

TEST(ImageCodec, SixteenBitAndAlphaAreNormalisedAndMarkedChanged) {
  cv::Mat sixteen(4, 5, CV_16UC1, cv::Scalar(0x1234));
  cv::Mat decoded;
  ImageFileType type;
  bool unchanged = true;
  ASSERT_TRUE(DecodeImageBytes(Encode(sixteen, ".png"), &decoded, &type, &unchanged).ok());
  EXPECT_FALSE(unchanged);
  EXPECT_EQ(decoded.type(), CV_8UC1);
  EXPECT_EQ(decoded.at<uint8_t>(0, 0), 0x12);

  cv::Mat bgra(4, 5, CV_8UC4, cv::Scalar(10, 20, 30, 40));
  ASSERT_TRUE(DecodeImageBytes(Encode(bgra, ".png"), &decoded, &type, &unchanged).ok());
  EXPECT_FALSE(unchanged);
  EXPECT_EQ(decoded.type(), CV_8UC3);
  EXPECT_EQ(decoded.at<cv::Vec3b>(1, 1), cv::Vec3b(10, 20, 30));
}

TEST(ImageCodec, CorruptBytesAreAnErrorNotACrash) {
  cv::Mat decoded;
  ImageFileType type;
  bool unchanged = false;
  EXPECT_FALSE(DecodeImageBytes("", &decoded, &type, &unchanged).ok());
  EXPECT_FALSE(DecodeImageBytes("this is not an image", &decoded, &type, &unchanged).ok());
  std::string png = Encode(testing_util::MakeTestImage(64, 64, 3, 5), ".png");
  png.resize(png.size() / 3);  // truncated file
  EXPECT_FALSE(DecodeImageBytes(png, &decoded, &type, &unchanged).ok());
  std::string jpeg = Encode(testing_util::MakeTestImage(64, 64, 3, 5), ".jpg");
  jpeg.resize(20);
  EXPECT_FALSE(DecodeImageBytes(jpeg, &decoded, &type, &unchanged).ok());
}

TEST(ImageCodec, ColourPolicy) {
  const cv::Mat bgr = testing_util::MakeTestImage(6, 4, 3, 2);
  const cv::Mat gray = testing_util::MakeTestImage(6, 4, 1, 2);
  cv::Mat out;
  bool changed = true;
  ASSERT_TRUE(ApplyColorPolicy(bgr, "keep", &out, &changed).ok());
  EXPECT_FALSE(changed);
  EXPECT_EQ(out.channels(), 3);
  ASSERT_TRUE(ApplyColorPolicy(bgr, "gray", &out, &changed).ok());
  EXPECT_TRUE(changed);
  EXPECT_EQ(out.channels(), 1);
  ASSERT_TRUE(ApplyColorPolicy(gray, "gray", &out, &changed).ok());
  EXPECT_FALSE(changed);
  ASSERT_TRUE(ApplyColorPolicy(gray, "bgr", &out, &changed).ok());
  EXPECT_TRUE(changed);
  EXPECT_EQ(out.channels(), 3);
  EXPECT_EQ(out.at<cv::Vec3b>(2, 3)[1], gray.at<uint8_t>(2, 3));
  EXPECT_FALSE(ApplyColorPolicy(gray, "purple", &out, &changed).ok());
}

}  // namespace
}  // namespace mbslam
