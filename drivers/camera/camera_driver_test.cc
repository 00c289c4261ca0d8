#include "drivers/camera/camera_driver.h"

#include <gtest/gtest.h>

#include <deque>
#include <map>

#include "common/lcm/wire_check.h"
#include "common/util/time.h"
#include "drivers/camera/camera_messages.h"
#include "drivers/camera/camera_test_util.h"

namespace mbslam {
namespace {

// Collects what the driver publishes, decoded, in order.
class RecordingSink : public MessageSink {
 public:
  Status PublishRaw(const std::string& channel, int64_t utime, const void* data,
                    size_t size) override {
    const auto* bytes = static_cast<const uint8_t*>(data);
    events.push_back({channel, utime, std::vector<uint8_t>(bytes, bytes + size)});
    ++messages_;
    return fail ? Status::Error("disk full") : Status::Ok();
  }
  bool is_file() const override { return true; }
  std::string description() const override { return "recorder"; }

  template <typename Msg>
  std::vector<Msg> Decoded(const std::string& channel) const {
    std::vector<Msg> out;
    for (const Event& e : events) {
      if (e.channel != channel) continue;
      Msg msg{};
      EXPECT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &msg).ok());
      out.push_back(msg);
    }
    return out;
  }
  struct Event {
    std::string channel;
    int64_t utime;
    std::vector<uint8_t> data;
  };
  std::vector<Event> events;
  bool fail = false;
};

// A scripted source: each step is a frame, a bad frame, an error or (for live
// sources) a disconnect; Open() fails as many times as asked.
class FakeSource : public FrameSource {
 public:
  enum class Step { kFrame, kBad, kDisconnect };
  FakeSource(bool live, int n, int64_t period_us = 100000) : live_(live) {
    for (int i = 0; i < n; ++i) script_.push_back(Step::kFrame);
    period_us_ = period_us;
  }
  SourceStatus Open() override {
    ++opens;
    if (open_failures > 0) {
      --open_failures;
      return SourceStatus::Error(open_error, "fake camera absent");
    }
    return SourceStatus::Ok();
  }
  void Close() override { ++closes; }
  ReadResult Next(Frame* frame, SourceStatus* status) override {
    if (position_ >= script_.size()) return ReadResult::kEnd;
    const Step step = script_[position_];
    const int64_t index = static_cast<int64_t>(position_++);
    *frame = Frame();
    frame->index = index;
    switch (step) {
      case Step::kBad:
        *status = SourceStatus::Error(SourceError::kIo, "bad frame " + std::to_string(index));
        return ReadResult::kBadFrame;
      case Step::kDisconnect:
        *status = SourceStatus::Error(SourceError::kDisconnected, "fake camera unplugged");
        return ReadResult::kError;
      case Step::kFrame:
        break;
    }
    frame->utime = 1000000 + period_us_ * index;
    frame->image = testing_util::MakeTestImage(width, 12, 1, static_cast<int>(index));
    frame->has_truth_source = truth;
    if (truth && index % 2 == 0) frame->world_from_cam = Rigid3d();
    frame->truth_source = "fake";
    frame->origin = "fake " + std::to_string(index);
    return ReadResult::kFrame;
  }
  bool is_live() const override { return live_; }
  int64_t num_frames() const override { return live_ ? -1 : static_cast<int64_t>(script_.size()); }
  SourceStatus Rewind() override {
    position_ = 0;
    return SourceStatus::Ok();
  }
  bool SeekToIndex(int64_t index) override {
    position_ = static_cast<size_t>(index);
    return true;
  }
  std::string description() const override { return "fake"; }

  std::vector<Step> script_;
  int open_failures = 0;
  SourceError open_error = SourceError::kNoCamera;
  int opens = 0;
  int closes = 0;
  int width = 16;
  bool truth = false;

 private:
  bool live_;
  int64_t period_us_;
  size_t position_ = 0;
};

CameraDriverOptions FastOptions() {
  CameraDriverOptions options;
  options.playback.progress = false;
  options.playback.speed = 0.0;
  options.live.reconnect_interval_s = 0.01;
  return options;
}

TEST(CameraDriver, PublishesFramesCalibrationAndTruth) {
  FakeSource source(false, 25);  // 10 Hz for 2.5 s
  source.truth = true;
  RecordingSink sink;
  CameraDriverOptions options = FastOptions();
  options.calibration_period_s = 1.0;
  options.camera_name = "front";
  CameraDriver driver(options, &source, &sink);
  ASSERT_TRUE(driver.Run().ok());
  const auto images = sink.Decoded<mbslam::image_t>("CAMERA_IMAGE");
  ASSERT_EQ(images.size(), 25u);
  for (size_t i = 0; i < images.size(); ++i) {
    EXPECT_EQ(images[i].seq, static_cast<int64_t>(i));
    EXPECT_EQ(images[i].utime, 1000000 + 100000 * static_cast<int64_t>(i));
    EXPECT_EQ(images[i].camera_name, "front");
    cv::Mat decoded;
    ASSERT_TRUE(DecodeImageMessage(images[i], &decoded).ok());
    EXPECT_EQ(cv::norm(decoded, testing_util::MakeTestImage(16, 12, 1, static_cast<int>(i)), cv::NORM_INF), 0);
  }
  // Calibration with the first frame, then once per second of message time.
  const auto calibrations = sink.Decoded<mbslam::camera_calibration_t>("CAMERA_CALIBRATION");
  ASSERT_EQ(calibrations.size(), 3u);
  EXPECT_EQ(calibrations[0].utime, 1000000);
  EXPECT_EQ(calibrations[1].utime, 2000000);
  EXPECT_EQ(calibrations[0].width, 16);
  EXPECT_EQ(calibrations[0].camera_name, "front");
  EXPECT_EQ(sink.events[0].channel, "CAMERA_CALIBRATION");  // before the first image
  EXPECT_EQ(sink.events[1].channel, "CAMERA_IMAGE");
  const auto truth = sink.Decoded<mbslam::ground_truth_t>("GROUND_TRUTH");
  ASSERT_EQ(truth.size(), 25u);
  EXPECT_EQ(truth[3].frame_seq, 3);
  EXPECT_EQ(truth[3].has_camera, 0);
  EXPECT_EQ(truth[4].has_camera, 1);
  EXPECT_EQ(driver.stats().truth_missing, 12);
  for (const auto& e : sink.events) EXPECT_GE(e.utime, 1000000);  // log time = message time
}

TEST(CameraDriver, BadFramesAreCountedAndLeaveSeqGaps) {
  FakeSource source(false, 6);
  source.script_[2] = FakeSource::Step::kBad;
  source.script_[3] = FakeSource::Step::kBad;
  RecordingSink sink;
  CameraDriver driver(FastOptions(), &source, &sink);
  ASSERT_TRUE(driver.Run().ok());
  EXPECT_EQ(driver.stats().bad_frames, 2);
  EXPECT_EQ(driver.stats().frames_published, 4);
  const auto images = sink.Decoded<mbslam::image_t>("CAMERA_IMAGE");
  ASSERT_EQ(images.size(), 4u);
  EXPECT_EQ(images[2].seq, 4);
  EXPECT_NE(driver.Summary().find("2 bad frames"), std::string::npos) << driver.Summary();
}

TEST(CameraDriver, FramesOfAnotherSizeThanTheCalibrationAreSkipped) {
  FakeSource source(false, 3);
  RecordingSink sink;
  CameraDriver driver(FastOptions(), &source, &sink);
  source.width = 16;
  ASSERT_TRUE(driver.Run().ok());
  EXPECT_EQ(driver.stats().frames_published, 3);

  const std::string dir = testing_util::MakeTempDir("calib");
  testing_util::WriteTextFile(dir + "/c.yaml",
                              "image_width: 20\nimage_height: 12\n"
                              "camera_matrix: {rows: 3, cols: 3, data: [10, 0, 10, 0, 10, 6, 0, 0, 1]}\n");
  CameraDriverOptions options = FastOptions();
  options.calibration_file = dir + "/c.yaml";
  FakeSource other(false, 3);
  RecordingSink sink2;
  CameraDriver mismatched(options, &other, &sink2);
  const SourceStatus st = mismatched.Run();
  EXPECT_EQ(st.kind(), SourceError::kConfig);
  EXPECT_NE(st.message().find("20x12"), std::string::npos) << st.message();
  options.calibration_file = dir + "/missing.yaml";
  CameraDriver missing(options, &other, &sink2);
  EXPECT_EQ(missing.Run().kind(), SourceError::kConfig);
}

TEST(CameraDriver, AllFramesBadIsAnError) {
  FakeSource source(false, 3);
  for (auto& s : source.script_) s = FakeSource::Step::kBad;
  RecordingSink sink;
  CameraDriver driver(FastOptions(), &source, &sink);
  EXPECT_EQ(driver.Run().kind(), SourceError::kIo);
}

TEST(CameraDriver, RangeByIndexAndTime) {
  FakeSource source(false, 20);
  RecordingSink sink;
  CameraDriverOptions options = FastOptions();
  options.playback.start_frame = 5;
  options.playback.end_frame = 15;
  options.playback.start_s = 0.2;  // relative to frame 5
  options.playback.end_s = 0.6;
  CameraDriver driver(options, &source, &sink);
  ASSERT_TRUE(driver.Run().ok());
  const auto images = sink.Decoded<mbslam::image_t>("CAMERA_IMAGE");
  ASSERT_EQ(images.size(), 5u);  // frames 7..11
  EXPECT_EQ(images.front().utime, 1700000);
  EXPECT_EQ(images.back().utime, 2100000);
}

TEST(CameraDriver, LoopsKeepTimeIncreasing) {
  FakeSource source(false, 4);
  RecordingSink sink;
  CameraDriverOptions options = FastOptions();
  options.playback.loops = 3;
  CameraDriver driver(options, &source, &sink);
  ASSERT_TRUE(driver.Run().ok());
  const auto images = sink.Decoded<mbslam::image_t>("CAMERA_IMAGE");
  ASSERT_EQ(images.size(), 12u);
  for (size_t i = 0; i < images.size(); ++i) {
    EXPECT_EQ(images[i].seq, static_cast<int64_t>(i));
    EXPECT_EQ(images[i].utime, 1000000 + 100000 * static_cast<int64_t>(i));
  }
  EXPECT_EQ(driver.stats().loops_done, 3);
}

TEST(CameraDriver, PacesFileSourcesOnABus) {
  FakeSource source(false, 6, 100000);  // 0.5 s of data
  Status status;
  std::unique_ptr<LcmBus> bus = LcmBus::Create("memq://", &status);
  ASSERT_TRUE(bus);
  LcmBusSink sink(bus.get());
  CameraDriverOptions options = FastOptions();
  options.playback.speed = 2.0;
  CameraDriver driver(options, &source, &sink);
  const int64_t start = MonotonicUtime();
  ASSERT_TRUE(driver.Run().ok());
  const int64_t elapsed = MonotonicUtime() - start;
  EXPECT_GE(elapsed, 240000);  // 0.5 s at 2x
  EXPECT_LT(elapsed, 1000000);
}

TEST(CameraDriver, LostLiveCameraIsAnErrorWithoutReconnect) {
  FakeSource source(true, 5);
  source.script_[3] = FakeSource::Step::kDisconnect;
  RecordingSink sink;
  CameraDriver driver(FastOptions(), &source, &sink);
  const SourceStatus st = driver.Run();
  EXPECT_EQ(st.kind(), SourceError::kDisconnected);
  EXPECT_EQ(driver.stats().frames_published, 3);
}

TEST(CameraDriver, LostLiveCameraReconnectsWhenAsked) {
  FakeSource source(true, 6);
  source.script_[2] = FakeSource::Step::kDisconnect;
  RecordingSink sink;
  CameraDriverOptions options = FastOptions();
  options.live.reconnect = true;
  CameraDriver driver(options, &source, &sink);
  ASSERT_TRUE(driver.Run().ok());
  EXPECT_EQ(driver.stats().reconnects, 1);
  EXPECT_EQ(driver.stats().frames_published, 5);
}

TEST(CameraDriver, MissingCameraAtStartRetriesThenGivesUp) {
  FakeSource source(true, 3);
  source.open_failures = 2;
  RecordingSink sink;
  CameraDriverOptions options = FastOptions();
  options.live.reconnect = true;
  CameraDriver driver(options, &source, &sink);
  ASSERT_TRUE(driver.Run().ok());
  EXPECT_EQ(source.opens, 3);
  EXPECT_EQ(driver.stats().frames_published, 3);

  FakeSource absent(true, 3);
  absent.open_failures = 100;
  options.live.max_reconnect_attempts = 4;
  CameraDriver giving_up(options, &absent, &sink);
  const SourceStatus st = giving_up.Run();
  EXPECT_EQ(st.kind(), SourceError::kNoCamera);
  EXPECT_EQ(absent.opens, 4);
  EXPECT_NE(st.message().find("gave up after 4"), std::string::npos);

  FakeSource bad_mode(true, 3);
  bad_mode.open_failures = 1;
  bad_mode.open_error = SourceError::kBadMode;  // not retried
  CameraDriver refused(options, &bad_mode, &sink);
  EXPECT_EQ(refused.Run().kind(), SourceError::kBadMode);
  EXPECT_EQ(bad_mode.opens, 1);

  FakeSource no_retry(true, 3);
  no_retry.open_failures = 1;
  CameraDriver plain(FastOptions(), &no_retry, &sink);
  EXPECT_EQ(plain.Run().kind(), SourceError::kNoCamera);
}

TEST(CameraDriver, OutputFailureStops) {
  FakeSource source(false, 3);
  RecordingSink sink;
  sink.fail = true;
  CameraDriver driver(FastOptions(), &source, &sink);
  EXPECT_EQ(driver.Run().kind(), SourceError::kOutput);
}

TEST(CameraDriver, SourceFactory) {
  CameraDriverOptions options;
  for (const char* s : {"dc1394", "v4l2", "video", "folder", "tum", "kitti", "tartanair", "sequence"}) {
    options.source = s;
    ASSERT_TRUE(options.Check()) << s;
    std::unique_ptr<FrameSource> source = CreateFrameSource(options);
    ASSERT_TRUE(source) << s;
    EXPECT_EQ(source->is_live(), IsLiveCameraSource(s)) << s;
  }
  options.source = "webcam";
  EXPECT_FALSE(options.Check());
}

}  // namespace
}  // namespace mbslam
