#include "services/perception/pipeline/pipeline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <mutex>
#include <thread>

namespace mbslam {
namespace {

// Records the order of events it sees; optionally slow.
class RecordingProcessor : public FrameProcessor {
 public:
  explicit RecordingProcessor(int sleep_ms = 0) : sleep_ms_(sleep_ms) {}
  void OnOdometry(const OdometrySample& o) override {
    std::lock_guard<std::mutex> lock(mutex_);
    events.push_back("o" + std::to_string(o.utime));
  }
  FrameResult ProcessFrame(const ImageFrame& f) override {
    if (sleep_ms_ > 0) std::this_thread::sleep_for(std::chrono::milliseconds(sleep_ms_));
    std::lock_guard<std::mutex> lock(mutex_);
    events.push_back("i" + std::to_string(f.utime));
    EXPECT_EQ(f.gray.cols, 8);
    FrameResult r;
    r.utime = f.utime;
    r.frame_seq = f.seq;
    return r;
  }
  void Finish() override { finished = true; }
  std::vector<std::string> events;
  bool finished = false;

 private:
  int sleep_ms_;
  std::mutex mutex_;
};

class CountingSink : public OutputSink {
 public:
  void OnFrameResult(const FrameResult& r) override { utimes.push_back(r.utime); }
  std::vector<int64_t> utimes;
};

RawImage Image(int64_t utime) {
  RawImage raw;
  raw.utime = utime;
  raw.seq = utime;
  raw.width = 8;
  raw.height = 4;
  raw.row_stride = 8;
  raw.encoding = ImageEncoding::kGray8;
  raw.bytes.assign(32, 7);
  return raw;
}

OdometrySample Odom(int64_t utime) {
  OdometrySample o;
  o.utime = utime;
  return o;
}

TEST(Pipeline, LockstepProcessesEveryEventInOrder) {
  PipelineOptions options;
  options.mode = "lockstep";
  options.lockstep_queue_capacity = 2;
  RecordingProcessor processor(/*sleep_ms=*/1);
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  pipeline.Start();
  std::vector<std::string> expected;
  for (int i = 1; i <= 50; ++i) {
    pipeline.Push(Odom(i * 100 - 50));
    expected.push_back("o" + std::to_string(i * 100 - 50));
    // An image waits for the odometry that covers its time (the next sample).
    if (i > 1) expected.push_back("i" + std::to_string((i - 1) * 100));
    pipeline.Push(Image(i * 100));
  }
  expected.push_back("i5000");  // flushed at the end of the stream
  pipeline.Stop();
  EXPECT_EQ(processor.events, expected);
  EXPECT_EQ(sink.utimes.size(), 50u);
  EXPECT_TRUE(processor.finished);
  EXPECT_EQ(pipeline.frames_processed(), 50);
  EXPECT_EQ(counters.Get(counter::kImageDroppedStale), 0);
}

TEST(Pipeline, RealtimeDropsStaleFramesAndCountsThem) {
  PipelineOptions options;
  options.mode = "realtime";
  options.image_queue_capacity = 1;
  RecordingProcessor processor(/*sleep_ms=*/20);
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  pipeline.Start();
  for (int i = 1; i <= 40; ++i) {
    pipeline.Push(Image(i * 1000));
    pipeline.Push(Odom(i * 1000 + 1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  pipeline.Stop();
  const int64_t processed = pipeline.frames_processed();
  const int64_t dropped = counters.Get(counter::kImageDroppedStale);
  EXPECT_LT(processed, 40);
  EXPECT_GT(dropped, 0);
  EXPECT_EQ(processed + dropped, 40) << "every frame is either processed or counted";
  // Odometry is never dropped by the image policy.
  int odometry = 0;
  for (const auto& e : processor.events) odometry += e[0] == 'o';
  EXPECT_EQ(odometry, 40);
  // The newest frame survives.
  EXPECT_EQ(sink.utimes.back(), 40000);
}

TEST(Pipeline, BadImageIsCountedNotFatal) {
  PipelineOptions options;
  options.mode = "lockstep";
  RecordingProcessor processor;
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  pipeline.Start();
  RawImage broken = Image(1);
  broken.encoding = ImageEncoding::kJpeg;  // bytes are not a JPEG
  pipeline.Push(broken);
  pipeline.Push(Image(2));
  pipeline.Stop();
  EXPECT_EQ(counters.Get(counter::kImageDecompressError), 1);
  EXPECT_EQ(pipeline.frames_processed(), 1);
}

TEST(Pipeline, StatusReportsStagesQueuesAndDegradation) {
  PipelineOptions options;
  options.mode = "lockstep";
  RecordingProcessor processor;
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  PipelineStatus s0 = pipeline.BuildStatus(1);
  EXPECT_EQ(s0.state, ServiceState::kStarting);
  pipeline.Start();
  for (int i = 1; i <= 5; ++i) pipeline.Push(Image(i * 33333));
  pipeline.Stop();
  counters.Increment(counter::kImageTimeBackwards);
  PipelineStatus s = pipeline.BuildStatus(2);
  EXPECT_EQ(s.frames_received, 5);
  EXPECT_EQ(s.frames_processed, 5);
  EXPECT_EQ(s.queues.size(), 3u);
  bool has_decode = false;
  for (const auto& st : s.stages) has_decode |= st.name == "decode" && st.timing.count == 5;
  EXPECT_TRUE(has_decode);
  EXPECT_EQ(s.state, ServiceState::kStopping);
  bool counted = false;
  for (const auto& [n, v] : s.counters) counted |= n == counter::kImageTimeBackwards && v == 1;
  EXPECT_TRUE(counted);
}

// The resident set at every status; the heap figures (mallinfo2, which holds the
// allocator's locks) at most every heap_stats_period_us, and never with 0.
TEST(Pipeline, StatusSamplesTheHeapAtItsOwnPeriod) {
  PipelineOptions options;
  options.heap_stats_period_us = 10000000;
  RecordingProcessor processor;
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  const PipelineStatus first = pipeline.BuildStatus(1000000);
  EXPECT_GT(first.memory.rss_bytes, 0);
  if (first.memory.heap_in_use_bytes < 0) GTEST_SKIP() << "no glibc heap figures in this build";
  std::vector<char> grown(size_t{64} << 20, 1);  // 64 MB more in use
  const PipelineStatus within = pipeline.BuildStatus(5000000);
  EXPECT_EQ(within.memory.heap_in_use_bytes, first.memory.heap_in_use_bytes);  // not sampled again
  EXPECT_GT(within.memory.rss_bytes, first.memory.rss_bytes + (int64_t{32} << 20));  // fresh
  const PipelineStatus after = pipeline.BuildStatus(11000000);
  EXPECT_GT(after.memory.heap_in_use_bytes, first.memory.heap_in_use_bytes + (int64_t{60} << 20));

  options.heap_stats_period_us = 0;
  PerceptionPipeline never(options, &processor, &sink, &counters, &timers);
  const PipelineStatus off = never.BuildStatus(1000000);
  EXPECT_GT(off.memory.rss_bytes, 0);
  EXPECT_EQ(off.memory.heap_in_use_bytes, -1);
  EXPECT_EQ(off.memory.heap_held_bytes, -1);
  EXPECT_GT(grown.back(), 0);
}

TEST(Pipeline, LockstepNewTimelineStartsOverThenWaitsForItsOwnOdometry) {
  PipelineOptions options;
  options.mode = "lockstep";
  RecordingProcessor processor;
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  pipeline.Start();
  pipeline.Push(Odom(50));
  pipeline.Push(Image(100));
  pipeline.Push(Odom(150));
  pipeline.Push(Image(200));
  pipeline.Push(Odom(250));
  RawImage reset = Image(10);  // time went back for good
  reset.timeline_reset = true;
  pipeline.Push(reset);
  pipeline.Push(Odom(20));
  pipeline.Push(Image(30));
  pipeline.Push(Odom(40));
  pipeline.Stop();
  // The first image of the new timeline goes first (the processor starts over before
  // the new odometry arrives); the old timeline's odometry (up to 250) must not let the
  // next images through before their own.
  const std::vector<std::string> expected = {"o50", "o150", "i100", "o250", "i200",
                                             "i10", "o20",  "o40",  "i30"};
  EXPECT_EQ(processor.events, expected);
}

// Returns the tracking states of a script, one per frame.
class ScriptedProcessor : public FrameProcessor {
 public:
  explicit ScriptedProcessor(std::vector<TrackingState> script) : script_(std::move(script)) {}
  void OnOdometry(const OdometrySample&) override {}
  FrameResult ProcessFrame(const ImageFrame& f) override {
    FrameResult r;
    r.utime = f.utime;
    r.camera_pose.tracking_state = script_[std::min(next_++, script_.size() - 1)];
    return r;
  }
  void Finish() override {}

 private:
  std::vector<TrackingState> script_;
  size_t next_ = 0;
};

TEST(Pipeline, TrackingLossAndRecoveryAreCountedAndReported) {
  PipelineOptions options;
  options.mode = "lockstep";
  using T = TrackingState;
  ScriptedProcessor processor({T::kNotInitialized, T::kInitializing, T::kOk, T::kOk, T::kLost, T::kLost,
                               T::kNotInitialized, T::kInitializing, T::kRelocalized, T::kOk, T::kLost});
  CountingSink sink;
  Counters counters;
  StageTimers timers;
  PerceptionPipeline pipeline(options, &processor, &sink, &counters, &timers);
  pipeline.Start();
  for (int i = 1; i <= 10; ++i) pipeline.Push(Image(i * 100));
  // Let the ten frames through before building a status mid-run.
  for (int i = 0; i < 500 && pipeline.frames_processed() < 10; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  ASSERT_EQ(pipeline.frames_processed(), 10);
  // The first initialisation is not a recovery; the way back after the loss is.
  EXPECT_EQ(counters.Get(counter::kTrackingLost), 1);
  EXPECT_EQ(counters.Get(counter::kTrackingRecovered), 1);
  const PipelineStatus ok = pipeline.BuildStatus(1);
  EXPECT_EQ(ok.message.find("; tracking "), std::string::npos) << ok.message;
  pipeline.Push(Image(1100));
  for (int i = 0; i < 500 && pipeline.frames_processed() < 11; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  EXPECT_EQ(counters.Get(counter::kTrackingLost), 2);
  const PipelineStatus lost = pipeline.BuildStatus(2);
  EXPECT_EQ(lost.state, ServiceState::kDegraded);
  EXPECT_NE(lost.message.find("tracking_lost +1"), std::string::npos) << lost.message;
  EXPECT_NE(lost.message.find("tracking lost"), std::string::npos) << lost.message;
  pipeline.Stop();
}

}  // namespace
}  // namespace mbslam
