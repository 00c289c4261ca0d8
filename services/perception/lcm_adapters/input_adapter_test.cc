#include "services/perception/lcm_adapters/input_adapter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <mutex>

#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "common/lcm/wire_check.h"

namespace mbslam {
namespace {

class Recorder : public FrameProcessor {
 public:
  void OnOdometry(const OdometrySample& o) override { odometry.push_back(o.utime); }
  FrameResult ProcessFrame(const ImageFrame& f) override {
    images.push_back(f.utime);
    resets += f.timeline_reset;
    fx.push_back(f.intrinsics ? f.intrinsics->fx : -1.0);
    return FrameResult();
  }
  std::vector<int64_t> images, odometry;
  std::vector<double> fx;
  int resets = 0;
};

class NullSink : public OutputSink {
 public:
  void OnFrameResult(const FrameResult&) override {}
};

mbslam::image_t Image(int64_t utime, int64_t seq, int w = 16, int h = 8) {
  mbslam::image_t m{};
  m.utime = utime;
  m.seq = seq;
  m.camera_name = "cam";
  m.width = w;
  m.height = h;
  m.row_stride = w;
  m.encoding = mbslam::image_t::ENCODING_GRAY8;
  m.data.assign(static_cast<size_t>(w * h), 100);
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

struct Fixture {
  Fixture() {
    options.mode = "lockstep";
    pipeline = std::make_unique<PerceptionPipeline>(options, &processor, &sink, &counters, &timers);
    Status s;
    adapter = InputAdapter::Create(input, options, pipeline.get(), &counters, &s);
    pipeline->Start();
  }
  void Feed(const mbslam::image_t& m) {
    const auto b = mbslam::EncodeLcmMessage(m);
    adapter->HandleImage(b.data(), b.size(), 1);
  }
  void Finish() { pipeline->Stop(); }
  PipelineOptions options;
  InputOptions input;
  Recorder processor;
  NullSink sink;
  Counters counters;
  StageTimers timers;
  std::unique_ptr<PerceptionPipeline> pipeline;
  std::unique_ptr<InputAdapter> adapter;
};

TEST(InputAdapter, CorruptTruncatedAndOversizedImagesAreCounted) {
  Fixture f;
  f.Feed(Image(1000, 0));
  std::vector<uint8_t> bytes = mbslam::EncodeLcmMessage(Image(2000, 1));
  f.adapter->HandleImage(bytes.data(), bytes.size() / 2, 1);  // truncated
  bytes[2] ^= 0xFF;  // corrupted type fingerprint
  f.adapter->HandleImage(bytes.data(), bytes.size(), 1);
  std::vector<uint8_t> garbage(5000, 0x5A);
  f.adapter->HandleImage(garbage.data(), garbage.size(), 1);
  mbslam::image_t wrong = Image(3000, 2);
  wrong.data.resize(10);
  wrong.size = 10;
  f.Feed(wrong);  // fewer bytes than width * height
  mbslam::image_t huge = Image(4000, 3);
  huge.width = 100000;
  f.Feed(huge);
  mbslam::image_t enc = Image(5000, 4);
  enc.encoding = 42;
  f.Feed(enc);
  f.Feed(Image(6000, 5));
  f.Finish();
  EXPECT_EQ(f.processor.images, (std::vector<int64_t>{1000, 6000}));
  EXPECT_EQ(f.counters.Get(counter::kImageDecodeError), 3);
  EXPECT_EQ(f.counters.Get(counter::kImageSizeMismatch), 1);
  EXPECT_EQ(f.counters.Get(counter::kImageBadSize), 1);
  EXPECT_EQ(f.counters.Get(counter::kImageUnknownEncoding), 1);
  EXPECT_EQ(f.pipeline->BuildStatus(0).frames_rejected, 6);
}

TEST(InputAdapter, TimeBackwardsRejectedThenNewTimeline) {
  Fixture f;
  f.Feed(Image(10000000, 0));
  f.Feed(Image(10033000, 1));
  f.Feed(Image(10010000, 2));  // back: rejected
  f.Feed(Image(10066000, 3));
  // A replay loop: time restarts at 0 and stays there.
  for (int i = 0; i < 20; ++i) f.Feed(Image(1000 + i * 33000, 100 + i));
  f.Finish();
  EXPECT_EQ(f.counters.Get(counter::kImageTimeBackwards), 1 + 14);
  EXPECT_EQ(f.processor.resets, 1);
  EXPECT_EQ(f.processor.images.size(), 3u + 6u);
}

TEST(InputAdapter, SeqGapsAndTimeJumpsAreReported) {
  Fixture f;
  f.Feed(Image(1000000, 0));
  f.Feed(Image(1033000, 1));
  f.Feed(Image(1133000, 4));            // 2 frames lost upstream
  f.Feed(Image(9000000, 5));            // 7.9 s jump
  f.Finish();
  EXPECT_EQ(f.counters.Get(counter::kImageSeqGap), 2);
  EXPECT_EQ(f.counters.Get(counter::kImageTimeJump), 1);
  EXPECT_EQ(f.processor.images.size(), 4u);
}

TEST(InputAdapter, CalibrationMessagesValidatedAndApplied) {
  Fixture f;
  mbslam::camera_calibration_t c{};
  c.camera_name = "cam";
  c.width = 16;
  c.height = 8;
  c.fx = 20;
  c.fy = 20;
  c.cx = 7.5;
  c.cy = 3.5;
  c.distortion_model = mbslam::camera_calibration_t::DISTORTION_NONE;
  mbslam::camera_calibration_t bad = c;
  bad.fx = NAN;
  auto b = mbslam::EncodeLcmMessage(bad);
  f.adapter->HandleCalibration(b.data(), b.size());
  f.Feed(Image(1000, 0));  // uncalibrated: fallback f = width
  b = mbslam::EncodeLcmMessage(c);
  f.adapter->HandleCalibration(b.data(), b.size());
  f.Feed(Image(2000, 1));
  mbslam::camera_calibration_t other = c;
  other.width = 32;
  b = mbslam::EncodeLcmMessage(other);
  f.adapter->HandleCalibration(b.data(), b.size());
  f.Feed(Image(3000, 2));  // size differs from calibration: rejected
  f.Finish();
  EXPECT_EQ(f.counters.Get(counter::kCalibrationInvalid), 1);
  EXPECT_EQ(f.counters.Get(counter::kImageUncalibrated), 1);
  EXPECT_EQ(f.counters.Get(counter::kImageCalibrationMismatch), 1);
  ASSERT_EQ(f.processor.fx.size(), 2u);
  EXPECT_DOUBLE_EQ(f.processor.fx[0], 16.0);
  EXPECT_DOUBLE_EQ(f.processor.fx[1], 20.0);
}

TEST(InputAdapter, OdometryNaNAndTimeBackwardsCounted) {
  Fixture f;
  mbslam::odometry_t o{};
  o.utime = 1000;
  o.orientation[0] = 1.0;
  auto b = mbslam::EncodeLcmMessage(o);
  f.adapter->HandleOdometry(b.data(), b.size());
  o.utime = 500;
  b = mbslam::EncodeLcmMessage(o);
  f.adapter->HandleOdometry(b.data(), b.size());
  o.utime = 2000;
  o.position[1] = INFINITY;
  b = mbslam::EncodeLcmMessage(o);
  f.adapter->HandleOdometry(b.data(), b.size());
  o.position[1] = 0;
  o.orientation[0] = 0.5;  // not unit
  b = mbslam::EncodeLcmMessage(o);
  f.adapter->HandleOdometry(b.data(), b.size());
  f.adapter->HandleOdometry(b.data(), 7);
  f.Finish();
  EXPECT_EQ(f.processor.odometry, (std::vector<int64_t>{1000}));
  EXPECT_EQ(f.counters.Get(counter::kOdometryTimeBackwards), 1);
  EXPECT_EQ(f.counters.Get(counter::kOdometryInvalid), 2);
  EXPECT_EQ(f.counters.Get(counter::kOdometryDecodeError), 1);
}

// Regression (issue 9): an image whose data holds more than width * height * channels
// bytes disagrees with its header: a counted drop, like one holding too few.
TEST(InputAdapter, ImageWithMoreDataThanItsSizeIsACountedDrop) {
  Fixture f;
  mbslam::image_t padded = Image(1000, 0);
  padded.data.resize(padded.data.size() * 3, 1);
  padded.size = static_cast<int32_t>(padded.data.size());
  f.Feed(padded);
  mbslam::image_t huge = Image(2000, 1, 16, 8);
  huge.width = 8192;  // 8192 x 8 gray announced, 128 bytes sent
  huge.row_stride = 8192;
  f.Feed(huge);
  f.Feed(Image(3000, 2));
  f.Finish();
  EXPECT_EQ(f.counters.Get(counter::kImageSizeMismatch), 2);
  EXPECT_EQ(f.processor.images, (std::vector<int64_t>{3000}));
}

// Regression (issue 9): times and sequence numbers at the ends of int64 are handled
// without overflow (utime - last_utime and last_seq + 1 were undefined there).
TEST(InputAdapter, ExtremeTimesAndSequenceNumbers) {
  Fixture f;
  const int64_t max = std::numeric_limits<int64_t>::max();
  const int64_t min = std::numeric_limits<int64_t>::min();
  f.Feed(Image(-5000000, max));       // negative time, largest seq
  f.Feed(Image(max, max));            // time jumps by more than int64 holds
  f.Feed(Image(min, min));            // back to the smallest: rejected
  f.Finish();
  EXPECT_EQ(f.processor.images, (std::vector<int64_t>{-5000000, max}));
  EXPECT_EQ(f.counters.Get(counter::kImageTimeJump), 1);
  EXPECT_EQ(f.counters.Get(counter::kImageTimeBackwards), 1);
  EXPECT_EQ(f.counters.Get(counter::kImageSeqGap), 0);
}

}  // namespace
}  // namespace mbslam
