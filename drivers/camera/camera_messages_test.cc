#include "drivers/camera/camera_messages.h"

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/camera/camera_test_util.h"

namespace mbslam {
namespace {

Frame MakeFrame(int channels, int seed) {
  Frame f;
  f.image = testing_util::MakeTestImage(41, 23, channels, seed);
  f.utime = 123456;
  return f;
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(CameraMessages, RawFramesRoundTripBitExact) {
  for (int channels : {1, 3}) {
    const Frame frame = MakeFrame(channels, channels);
    ImageOutputOptions options;
    mbslam::image_t msg{};
    ASSERT_TRUE(EncodeFrameImage(frame, options, &msg).ok());
    EXPECT_EQ(msg.encoding, channels == 1 ? mbslam::image_t::ENCODING_GRAY8
                                          : mbslam::image_t::ENCODING_BGR8);
    EXPECT_EQ(msg.width, 41);
    EXPECT_EQ(msg.height, 23);
    EXPECT_EQ(msg.row_stride, 41 * channels);
    EXPECT_EQ(msg.size, 41 * 23 * channels);
    cv::Mat decoded;
    ASSERT_TRUE(DecodeImageMessage(msg, &decoded).ok());
    EXPECT_TRUE(Identical(decoded, frame.image));
  }
}

TEST(CameraMessages, PngIsLosslessJpegIsClose) {
  const Frame frame = MakeFrame(3, 9);
  ImageOutputOptions options;
  options.encoding = "png";
  mbslam::image_t msg{};
  ASSERT_TRUE(EncodeFrameImage(frame, options, &msg).ok());
  EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_PNG);
  EXPECT_EQ(msg.row_stride, 0);
  cv::Mat decoded;
  ASSERT_TRUE(DecodeImageMessage(msg, &decoded).ok());
  EXPECT_TRUE(Identical(decoded, frame.image));

  options.encoding = "jpeg";
  options.jpeg_quality = 98;
  Frame smooth;
  cv::GaussianBlur(frame.image, smooth.image, cv::Size(9, 9), 3.0);  // JPEG suits smooth images
  ASSERT_TRUE(EncodeFrameImage(smooth, options, &msg).ok());
  EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_JPEG);
  ASSERT_TRUE(DecodeImageMessage(msg, &decoded).ok());
  EXPECT_GT(cv::PSNR(decoded, smooth.image), 35.0);
}

TEST(CameraMessages, SourceEncodingPassesFileBytesThroughUnlessConverted) {
  Frame frame = MakeFrame(3, 4);
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", frame.image, jpeg));
  frame.image = cv::imdecode(jpeg, cv::IMREAD_UNCHANGED);
  frame.file_bytes.assign(jpeg.begin(), jpeg.end());
  frame.file_encoding = mbslam::image_t::ENCODING_JPEG;
  ImageOutputOptions options;
  options.encoding = "source";
  mbslam::image_t msg{};
  ASSERT_TRUE(EncodeFrameImage(frame, options, &msg).ok());
  EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_JPEG);
  EXPECT_EQ(msg.data, jpeg);
  cv::Mat decoded;
  ASSERT_TRUE(DecodeImageMessage(msg, &decoded).ok());
  EXPECT_TRUE(Identical(decoded, frame.image));

  options.color = "gray";  // conversion: the file no longer describes the pixels
  ASSERT_TRUE(EncodeFrameImage(frame, options, &msg).ok());
  EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_GRAY8);

  frame.file_bytes.clear();  // no file (e.g. a video frame): raw
  options.color = "keep";
  ASSERT_TRUE(EncodeFrameImage(frame, options, &msg).ok());
  EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_BGR8);
}

TEST(CameraMessages, DecoderRejectsInconsistentMessages) {
  mbslam::image_t msg{};
  ASSERT_TRUE(EncodeFrameImage(MakeFrame(1, 1), ImageOutputOptions(), &msg).ok());
  cv::Mat out;
  mbslam::image_t bad = msg;
  bad.height += 1;
  EXPECT_FALSE(DecodeImageMessage(bad, &out).ok());
  bad = msg;
  bad.size -= 1;
  EXPECT_FALSE(DecodeImageMessage(bad, &out).ok());
  bad = msg;
  bad.row_stride = 3;
  EXPECT_FALSE(DecodeImageMessage(bad, &out).ok());
  bad = msg;
  bad.encoding = 42;
  EXPECT_FALSE(DecodeImageMessage(bad, &out).ok());
  bad = msg;
  bad.encoding = mbslam::image_t::ENCODING_PNG;  // raw bytes are not a PNG
  EXPECT_FALSE(DecodeImageMessage(bad, &out).ok());
}

TEST(CameraMessages, RgbIsConvertedToBgr) {
  mbslam::image_t msg{};
  msg.width = 1;
  msg.height = 1;
  msg.row_stride = 3;
  msg.encoding = mbslam::image_t::ENCODING_RGB8;
  msg.data = {10, 20, 30};
  msg.size = 3;
  cv::Mat out;
  ASSERT_TRUE(DecodeImageMessage(msg, &out).ok());
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
}

TEST(CameraMessages, CalibrationMessage) {
  CameraIntrinsics c;
  c.width = 640;
  c.height = 480;
  c.fx = 535.4;
  c.fy = 539.2;
  c.cx = 320.1;
  c.cy = 247.6;
  c.model = DistortionModel::kRadTan;
  c.distortion = {0.1, -0.2, 0.001, 0.002};
  mbslam::camera_calibration_t msg{};
  FillCalibrationMessage(c, 77, "front", &msg);
  EXPECT_EQ(msg.utime, 77);
  EXPECT_EQ(msg.camera_name, "front");
  EXPECT_EQ(msg.width, 640);
  EXPECT_EQ(msg.fx, 535.4);
  EXPECT_EQ(msg.fy, 539.2);
  EXPECT_EQ(msg.cx, 320.1);
  EXPECT_EQ(msg.cy, 247.6);
  EXPECT_EQ(msg.distortion_model, mbslam::camera_calibration_t::DISTORTION_RADTAN);
  EXPECT_EQ(msg.num_distortion, 4);
  EXPECT_EQ(msg.distortion[1], -0.2);
}

TEST(CameraMessages, GroundTruthQuaternionIsWxyz) {
  Frame frame;
  frame.utime = 5;
  frame.truth_source = "tum";
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.9, 0.1, -0.3, 0.2).normalized();
  frame.world_from_cam = Rigid3d(q, Eigen::Vector3d(1, 2, 3));
  BodyTruth body;
  body.id = 3;
  body.name = "car";
  body.world_from_body = Rigid3d(q, Eigen::Vector3d(4, 5, 6));
  body.extent = Eigen::Vector3d(4, 2, 1.5);
  body.visible = true;
  frame.bodies.push_back(body);
  mbslam::ground_truth_t msg{};
  FillGroundTruthMessage(frame, 9, &msg);
  EXPECT_EQ(msg.frame_seq, 9);
  EXPECT_EQ(msg.has_camera, 1);
  EXPECT_EQ(msg.cam_position[2], 3.0);
  EXPECT_DOUBLE_EQ(msg.cam_orientation[0], q.w());
  EXPECT_DOUBLE_EQ(msg.cam_orientation[1], q.x());
  EXPECT_DOUBLE_EQ(msg.cam_orientation[3], q.z());
  ASSERT_EQ(msg.num_bodies, 1);
  EXPECT_EQ(msg.bodies[0].id, 3);
  EXPECT_EQ(msg.bodies[0].visible, 1);
  EXPECT_EQ(msg.bodies[0].extent[0], 4.0);

  frame.world_from_cam.reset();
  FillGroundTruthMessage(frame, 10, &msg);
  EXPECT_EQ(msg.has_camera, 0);
  EXPECT_EQ(msg.cam_orientation[0], 1.0);
}

}  // namespace
}  // namespace mbslam
