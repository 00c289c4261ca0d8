#include "drivers/camera/video_source.h"

#include <gtest/gtest.h>

#include <opencv2/videoio.hpp>

#include "drivers/camera/camera_test_util.h"

namespace mbslam {
namespace {

// A lossless (FFV1) video of `n` frames at 25 Hz.
std::string WriteVideo(int n, std::vector<cv::Mat>* frames) {
  const std::string path = testing_util::MakeTempDir("video") + "/clip.avi";
  cv::VideoWriter writer(path, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 25.0,
                         cv::Size(48, 32), true);
  EXPECT_TRUE(writer.isOpened());
  for (int i = 0; i < n; ++i) {
    frames->push_back(testing_util::MakeTestImage(48, 32, 3, i));
    writer.write(frames->back());
  }
  return path;
}

TEST(VideoSource, FramesAndTimesMatchAnIndependentDecode) {
  std::vector<cv::Mat> written;
  const std::string path = WriteVideo(12, &written);
  std::vector<cv::Mat> reference;
  cv::VideoCapture cap(path, cv::CAP_FFMPEG);
  for (cv::Mat m; cap.read(m);) reference.push_back(m.clone());
  ASSERT_EQ(reference.size(), 12u);

  VideoSource source(path, 10.0, 5000000);
  ASSERT_TRUE(source.Open().ok());
  EXPECT_EQ(source.num_frames(), 12);
  Frame frame;
  SourceStatus status;
  for (int i = 0; i < 12; ++i) {
    ASSERT_EQ(source.Next(&frame, &status), FrameSource::ReadResult::kFrame) << i;
    EXPECT_EQ(frame.index, i);
    EXPECT_EQ(frame.utime, 5000000 + 40000 * i);  // 25 Hz from the time origin
    EXPECT_EQ(cv::norm(frame.image, reference[static_cast<size_t>(i)], cv::NORM_INF), 0) << i;
  }
  EXPECT_EQ(source.Next(&frame, &status), FrameSource::ReadResult::kEnd);
  ASSERT_TRUE(source.Rewind().ok());
  ASSERT_TRUE(source.SeekToIndex(7));
  ASSERT_EQ(source.Next(&frame, &status), FrameSource::ReadResult::kFrame);
  EXPECT_EQ(frame.index, 7);
  EXPECT_EQ(frame.utime, 5000000 + 40000 * 7);
  EXPECT_EQ(cv::norm(frame.image, reference[7], cv::NORM_INF), 0);
}

TEST(VideoSource, MissingAndGarbageFiles) {
  VideoSource missing("/nonexistent/clip.avi", 10.0, 0);
  EXPECT_EQ(missing.Open().kind(), SourceError::kNotFound);
  const std::string garbage = testing_util::MakeTempDir("garbage") + "/clip.avi";
  testing_util::WriteTextFile(garbage, std::string(5000, 'x'));
  VideoSource bad(garbage, 10.0, 0);
  EXPECT_EQ(bad.Open().kind(), SourceError::kIo);
}

TEST(VideoSource, TruncatedFileEndsCleanly) {
  std::vector<cv::Mat> written;
  const std::string path = WriteVideo(20, &written);
  std::string bytes;
  {
    std::ifstream in(path, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::string cut = testing_util::MakeTempDir("cut") + "/clip.avi";
  {
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  }
  VideoSource source(cut, 10.0, 0);
  if (!source.Open().ok()) return;  // a decoder may refuse the cut file outright: fine
  Frame frame;
  SourceStatus status;
  int n = 0;
  for (FrameSource::ReadResult r; (r = source.Next(&frame, &status)) != FrameSource::ReadResult::kEnd;) {
    ASSERT_NE(r, FrameSource::ReadResult::kError);
    ASSERT_LT(++n, 100);
  }
  EXPECT_LT(n, 20);
}

}  // namespace
}  // namespace mbslam
