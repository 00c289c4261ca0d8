// The live sources on a machine without cameras: every failure must be a clear,
// typed error, never a hang or a crash.

#include <gtest/gtest.h>

#include <filesystem>

#include "common/util/time.h"
#include "drivers/camera/camera_test_util.h"
#include "drivers/camera/dc1394_source.h"
#include "drivers/camera/v4l2_source.h"

namespace mbslam {
namespace {

bool AnyDevNode(const std::string& prefix) {
  std::error_code ec;
  for (std::filesystem::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().rfind(prefix, 0) == 0) return true;
  }
  return false;
}

TEST(Dc1394Source, NoBusMeansNoCamera) {
  if (AnyDevNode("fw")) GTEST_SKIP() << "this machine has a FireWire bus";
  Dc1394Source source{Dc1394Options()};
  const int64_t start = MonotonicUtime();
  const SourceStatus st = source.Open();
  EXPECT_EQ(st.kind(), SourceError::kNoCamera);
  EXPECT_NE(st.message().find("IEEE 1394"), std::string::npos) << st.message();
  EXPECT_EQ(st.message().find('\n'), std::string::npos);
  EXPECT_LT(MonotonicUtime() - start, 5 * kUsecPerSec);
  Frame frame;
  SourceStatus read;
  EXPECT_EQ(source.Next(&frame, &read), FrameSource::ReadResult::kError);
  std::string report;
  EXPECT_EQ(ListDc1394Cameras(&report), 0);
  EXPECT_NE(report.find("no IEEE 1394 camera"), std::string::npos);
}

TEST(Dc1394Source, BadOptionsAreConfigErrorsBeforeTheBusIsTouched) {
  Dc1394Options options;
  options.video_mode = "640x480_MONO9";
  EXPECT_EQ(Dc1394Source(options).Open().kind(), SourceError::kConfig);
  options = Dc1394Options();
  options.framerate = 25.0;
  EXPECT_EQ(Dc1394Source(options).Open().kind(), SourceError::kConfig);
  options = Dc1394Options();
  options.guid = "not-a-guid";
  EXPECT_EQ(Dc1394Source(options).Open().kind(), SourceError::kConfig);
}

TEST(V4l2Source, MissingDeviceMeansNoCamera) {
  V4l2Options options;
  options.device = "/dev/video_mbslam_test_absent";
  V4l2Source source(options);
  const SourceStatus st = source.Open();
  EXPECT_EQ(st.kind(), SourceError::kNoCamera);
  EXPECT_NE(st.message().find("/dev/video_mbslam_test_absent"), std::string::npos);
  Frame frame;
  SourceStatus read;
  EXPECT_EQ(source.Next(&frame, &read), FrameSource::ReadResult::kError);
  EXPECT_EQ(read.kind(), SourceError::kDisconnected);
}

TEST(V4l2Source, DefaultDeviceOnThisMachine) {
  if (AnyDevNode("video")) GTEST_SKIP() << "this machine has a V4L2 device";
  V4l2Source source{V4l2Options()};
  const SourceStatus st = source.Open();
  EXPECT_EQ(st.kind(), SourceError::kNoCamera);
  EXPECT_NE(st.message().find("/dev/video0"), std::string::npos);
}

TEST(V4l2Source, NodesThatAreNotCameras) {
  const std::string file = testing_util::MakeTempDir("v4l2") + "/video0";
  testing_util::WriteTextFile(file, "x");
  EXPECT_EQ(CheckV4l2DeviceNode(file).kind(), SourceError::kConfig);
  // A character device that is not a camera: OpenCV must refuse it, quickly.
  V4l2Options options;
  options.device = "/dev/null";
  const int64_t start = MonotonicUtime();
  const SourceStatus st = V4l2Source(options).Open();
  EXPECT_FALSE(st.ok());
  EXPECT_LT(MonotonicUtime() - start, 5 * kUsecPerSec);
  EXPECT_EQ(V4l2DevicePath("3"), "/dev/video3");
  EXPECT_EQ(V4l2DevicePath("/dev/v4l/by-id/cam"), "/dev/v4l/by-id/cam");
}

}  // namespace
}  // namespace mbslam
