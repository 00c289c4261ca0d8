#include "drivers/camera/dc1394_modes.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <vector>

namespace mbslam {
namespace {

TEST(Dc1394Modes, NamesRoundTrip) {
  dc1394video_mode_t mode;
  ASSERT_TRUE(ParseDc1394VideoMode("640x480_MONO8", &mode).ok());
  EXPECT_EQ(mode, DC1394_VIDEO_MODE_640x480_MONO8);
  ASSERT_TRUE(ParseDc1394VideoMode("1024X768_yuv422", &mode).ok());
  EXPECT_EQ(mode, DC1394_VIDEO_MODE_1024x768_YUV422);
  EXPECT_EQ(Dc1394VideoModeName(DC1394_VIDEO_MODE_1600x1200_RGB8), "1600x1200_RGB8");
  ASSERT_TRUE(ParseDc1394VideoMode("format7_2", &mode).ok());
  EXPECT_TRUE(IsDc1394Format7(mode));
  EXPECT_FALSE(IsDc1394Format7(DC1394_VIDEO_MODE_640x480_RGB8));
  EXPECT_FALSE(ParseDc1394VideoMode("640x480_MONO9", &mode).ok());
  EXPECT_FALSE(ParseDc1394VideoMode("", &mode).ok());
}

TEST(Dc1394Modes, FrameRatesSpeedsCodingsGuids) {
  dc1394framerate_t rate;
  ASSERT_TRUE(ParseDc1394Framerate(7.5, &rate).ok());
  EXPECT_EQ(rate, DC1394_FRAMERATE_7_5);
  ASSERT_TRUE(ParseDc1394Framerate(240, &rate).ok());
  EXPECT_EQ(rate, DC1394_FRAMERATE_240);
  EXPECT_DOUBLE_EQ(Dc1394FramerateHz(DC1394_FRAMERATE_1_875), 1.875);
  EXPECT_DOUBLE_EQ(Dc1394FramerateHz(DC1394_FRAMERATE_30), 30.0);
  EXPECT_FALSE(ParseDc1394Framerate(25, &rate).ok());
  dc1394speed_t speed;
  ASSERT_TRUE(ParseDc1394IsoSpeed(800, &speed).ok());
  EXPECT_EQ(speed, DC1394_ISO_SPEED_800);
  EXPECT_FALSE(ParseDc1394IsoSpeed(500, &speed).ok());
  dc1394color_coding_t coding;
  ASSERT_TRUE(ParseDc1394ColorCoding("raw8", &coding).ok());
  EXPECT_EQ(coding, DC1394_COLOR_CODING_RAW8);
  EXPECT_EQ(Dc1394ColorCodingName(DC1394_COLOR_CODING_YUV411), "YUV411");
  uint64_t guid = 0;
  ASSERT_TRUE(ParseDc1394Guid("0x00b09d0100a1b2c3", &guid).ok());
  EXPECT_EQ(guid, 0x00b09d0100a1b2c3ull);
  EXPECT_EQ(FormatDc1394Guid(guid), "0x00b09d0100a1b2c3");
  EXPECT_FALSE(ParseDc1394Guid("0xZZ", &guid).ok());
  EXPECT_FALSE(ParseDc1394Guid("-1", &guid).ok());
}

dc1394video_frame_t MakeFrame(std::vector<uint8_t>* data, int w, int h, dc1394color_coding_t coding,
                              uint32_t stride) {
  dc1394video_frame_t f{};
  f.image = data->data();
  f.size[0] = static_cast<uint32_t>(w);
  f.size[1] = static_cast<uint32_t>(h);
  f.color_coding = coding;
  f.stride = stride;
  f.image_bytes = static_cast<uint32_t>(data->size());
  f.data_depth = 8;
  return f;
}

TEST(Dc1394Convert, Mono8WithRowPadding) {
  std::vector<uint8_t> data(6 * 3, 0xEE);  // stride 6 for width 4
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) data[static_cast<size_t>(r * 6 + c)] = static_cast<uint8_t>(10 * r + c);
  }
  const dc1394video_frame_t f = MakeFrame(&data, 4, 3, DC1394_COLOR_CODING_MONO8, 6);
  cv::Mat image;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  ASSERT_EQ(image.type(), CV_8UC1);
  EXPECT_EQ(image.at<uint8_t>(2, 3), 23);
  EXPECT_EQ(image.at<uint8_t>(1, 0), 10);
}

TEST(Dc1394Convert, Mono16BigEndianTwelveBit) {
  std::vector<uint8_t> data = {0x0F, 0xFF, 0x08, 0x00};  // 4095 and 2048, big-endian
  dc1394video_frame_t f = MakeFrame(&data, 2, 1, DC1394_COLOR_CODING_MONO16, 4);
  f.data_depth = 12;
  cv::Mat image;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  EXPECT_EQ(image.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(image.at<uint8_t>(0, 1), 128);
  f.little_endian = DC1394_TRUE;  // now 0xFF0F and 0x0008
  f.data_depth = 16;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  EXPECT_EQ(image.at<uint8_t>(0, 0), 0xFF);
  EXPECT_EQ(image.at<uint8_t>(0, 1), 0x00);
}

TEST(Dc1394Convert, Rgb8BecomesBgr) {
  std::vector<uint8_t> data = {1, 2, 3, 4, 5, 6};
  const dc1394video_frame_t f = MakeFrame(&data, 2, 1, DC1394_COLOR_CODING_RGB8, 0);
  cv::Mat image;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  EXPECT_EQ(image.at<cv::Vec3b>(0, 1), cv::Vec3b(6, 5, 4));
}

TEST(Dc1394Convert, Yuv422UyvyGrayStaysGray) {
  // U Y0 V Y1 with neutral chroma: gray levels 50 and 200.
  std::vector<uint8_t> data = {128, 50, 128, 200};
  dc1394video_frame_t f = MakeFrame(&data, 2, 1, DC1394_COLOR_CODING_YUV422, 4);
  f.yuv_byte_order = DC1394_BYTE_ORDER_UYVY;
  cv::Mat image;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  ASSERT_EQ(image.type(), CV_8UC3);
  const cv::Vec3b a = image.at<cv::Vec3b>(0, 0), b = image.at<cv::Vec3b>(0, 1);
  EXPECT_EQ(a[0], a[2]);
  EXPECT_NEAR(a[1], 50, 2);
  EXPECT_NEAR(b[1], 200, 2);
}

TEST(Dc1394Convert, Yuv411AndYuv444ThroughLibdc1394) {
  std::vector<uint8_t> yuv444 = {128, 90, 128, 128, 160, 128};  // U Y V per pixel
  const dc1394video_frame_t f = MakeFrame(&yuv444, 2, 1, DC1394_COLOR_CODING_YUV444, 0);
  cv::Mat image;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  EXPECT_NEAR(image.at<cv::Vec3b>(0, 1)[1], 160, 3);
  std::vector<uint8_t> yuv411(6, 128);  // 4 pixels: U Y0 Y1 V Y2 Y3
  const dc1394video_frame_t g = MakeFrame(&yuv411, 4, 1, DC1394_COLOR_CODING_YUV411, 0);
  ASSERT_TRUE(ConvertDc1394Frame(g, "none", &image).ok());
  EXPECT_EQ(image.cols, 4);
}

TEST(Dc1394Convert, Raw8BayerIsDemosaiced) {
  // An RGGB mosaic of a pure red scene: R sites 200, G and B sites 0.
  std::vector<uint8_t> data(8 * 8, 0);
  for (int r = 0; r < 8; r += 2) {
    for (int c = 0; c < 8; c += 2) data[static_cast<size_t>(r * 8 + c)] = 200;
  }
  dc1394video_frame_t f = MakeFrame(&data, 8, 8, DC1394_COLOR_CODING_RAW8, 8);
  f.color_filter = DC1394_COLOR_FILTER_RGGB;
  cv::Mat image;
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());  // the frame's own filter
  ASSERT_EQ(image.type(), CV_8UC3);
  const cv::Vec3b p = image.at<cv::Vec3b>(4, 4);
  EXPECT_GT(p[2], 150);  // red
  EXPECT_LT(p[0], 30);
  EXPECT_LT(p[1], 30);
  f.color_coding = DC1394_COLOR_CODING_MONO8;  // MONO8 stays gray unless a pattern is given
  ASSERT_TRUE(ConvertDc1394Frame(f, "none", &image).ok());
  EXPECT_EQ(image.channels(), 1);
  ASSERT_TRUE(ConvertDc1394Frame(f, "RGGB", &image).ok());
  EXPECT_EQ(image.channels(), 3);
  EXPECT_FALSE(ConvertDc1394Frame(f, "XXXX", &image).ok());
}

TEST(Dc1394Convert, ShortBuffersAndOddCodingsAreErrors) {
  std::vector<uint8_t> data(10, 0);
  dc1394video_frame_t f = MakeFrame(&data, 4, 4, DC1394_COLOR_CODING_MONO8, 4);
  cv::Mat image;
  EXPECT_FALSE(ConvertDc1394Frame(f, "none", &image).ok());  // 16 bytes needed
  f = MakeFrame(&data, 2, 1, DC1394_COLOR_CODING_MONO16S, 4);
  EXPECT_FALSE(ConvertDc1394Frame(f, "none", &image).ok());
  f = MakeFrame(&data, 2, 1, DC1394_COLOR_CODING_MONO8, 1);  // stride below width
  EXPECT_FALSE(ConvertDc1394Frame(f, "none", &image).ok());
  f.image = nullptr;
  EXPECT_FALSE(ConvertDc1394Frame(f, "none", &image).ok());
}

}  // namespace
}  // namespace mbslam
