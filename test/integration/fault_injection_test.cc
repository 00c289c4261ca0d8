// Fault injection: the perception service runs (in process, on memq://) on a
// simulated sequence rewritten with one fault at a time (test/tools/log_faults.h).
// For each fault: the service stays up and writes a decodable output log,
// PERCEPTION_STATUS counts what happened, and camera tracking is back within a
// stated number of processed frames after the fault ends. Each test prints its figures
// as one FAULT_JSON line (collected by scripts/eval.d/faults.sh).
//
// The input: scenario `static`, 320x240 at 15 Hz, 240 frames; ODOMETRY is synthesised
// from the ground-truth camera poses with the service's default base_from_cam, so the
// odometry agrees with the images.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <thread>

#include "common/util/atomic_file.h"
#include "common/util/logging.h"
#include "common/util/time.h"
#include "services/perception/perception_service.h"
#include "test/integration/fault_test_util.h"
#include "test/tools/log_faults.h"

namespace mbslam {
namespace {

using fault::LogEditor;
using fault_test::FaultReport;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct ServiceRun {
  Status finished;
  std::vector<mbslam::status_t> statuses;
  std::vector<mbslam::camera_pose_t> poses;
  std::map<std::string, int64_t> counters;  // of the final status
  fault_test::OutputLogCheck output;
  std::string summary_json;

  const mbslam::status_t& last() const { return statuses.back(); }
  int64_t C(const std::string& name) const {
    auto it = counters.find(name);
    return it == counters.end() ? 0 : it->second;
  }
  std::vector<std::string> States() const {
    std::set<std::string> seen;
    for (const auto& s : statuses) seen.insert(fault_test::StateName(s.state));
    return {seen.begin(), seen.end()};
  }
};

class FaultInjection : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    SetLogLevel(LogLevel::kWarning);
    std::string error;
    const std::string dir = fault_test::EnsureSequence(&error);
    if (dir.empty()) {
      setup_error_ = new std::string(error);
      return;
    }
    base_ = new LogEditor({});
    Status s = LogEditor::Load(dir + "/sequence.lcmlog", base_);
    if (s.ok()) {
      const OdometryOptions defaults;
      s = base_->AddOdometryFromTruth(defaults.base_from_cam_rotation.data(),
                                      defaults.base_from_cam_translation.data());
    }
    if (!s.ok()) setup_error_ = new std::string(s.message());
  }
  static void TearDownTestSuite() {
    delete base_;
    delete setup_error_;
    base_ = nullptr;
    setup_error_ = nullptr;
  }
  void SetUp() override {
    ASSERT_EQ(setup_error_, nullptr) << *setup_error_;
    ASSERT_EQ(base_->num_frames(), fault_test::kSequenceFrames);
  }

  static LogEditor Base() { return *base_; }
  static int64_t Us(double seconds) { return SecondsToUtime(seconds); }

  // Replays `log` through a fresh service. Lockstep: as fast as it goes. Realtime: each
  // event published at its log time / speed (wall clock), the service dropping stale frames.
  static ServiceRun Run(const LogEditor& log, bool realtime = false, double speed = 1.0) {
    ServiceRun run;
    const std::string work = testing_util::MakeTestTempDir("fault_run");
    PerceptionOptions options;
    options.pipeline.mode = realtime ? "realtime" : "lockstep";
    options.service.output_log = work + "/out.lcmlog";
    options.service.output_dir = work + "/result";
    Status s;
    std::unique_ptr<LcmBus> bus = LcmBus::Create("memq://", &s);
    EXPECT_TRUE(bus) << s.message();
    if (!bus) return run;
    std::unique_ptr<PerceptionService> service = PerceptionService::Create(options, &s, bus.get());
    EXPECT_TRUE(service) << s.message();
    if (!service) return run;
    bus->Subscribe(
        options.channels.perception_status,
        [&run](const std::string&, const uint8_t* d, size_t n, int64_t) {
          mbslam::status_t m{};
          if (DecodeLcmMessage(d, n, &m).ok()) run.statuses.push_back(std::move(m));
        },
        1 << 20);
    bus->Subscribe(
        options.channels.perception_camera_pose,
        [&run](const std::string&, const uint8_t* d, size_t n, int64_t) {
          mbslam::camera_pose_t m{};
          if (DecodeLcmMessage(d, n, &m).ok()) run.poses.push_back(m);
        },
        1 << 20);
    const std::vector<LcmLogEvent>& events = log.events();
    const int64_t wall0 = MonotonicUtime();
    const int64_t log0 = events.front().timestamp;
    for (const LcmLogEvent& e : events) {
      if (realtime) {
        const int64_t due = wall0 + static_cast<int64_t>(static_cast<double>(e.timestamp - log0) / speed);
        const int64_t wait = due - MonotonicUtime();
        if (wait > 0) std::this_thread::sleep_for(std::chrono::microseconds(wait));
      }
      bus->PublishRaw(e.channel, e.data.data(), static_cast<unsigned>(e.data.size()));
      while (bus->HandleTimeout(0) > 0) {
      }
      service->RunOnce(0);  // publishes PERCEPTION_STATUS when due
    }
    if (realtime) std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the frame in flight
    run.finished = service->Finish();
    while (bus->HandleTimeout(0) > 0) {
    }
    service.reset();
    if (!run.statuses.empty()) run.counters = fault_test::Counters(run.statuses.back());
    run.output = fault_test::CheckOutputLog(options.service.output_log);
    std::string summary;
    if (ReadFileToString(options.service.output_dir + "/summary.json", &summary).ok()) run.summary_json = summary;
    return run;
  }

  // What every fault must leave behind: a service that ran to the end, a final
  // status, a decodable output log with a pose per processed frame, written outputs.
  static void ExpectSurvived(const ServiceRun& run, FaultReport* report) {
    EXPECT_TRUE(run.finished.ok()) << run.finished.message();
    ASSERT_FALSE(run.statuses.empty()) << "no PERCEPTION_STATUS received";
    EXPECT_EQ(run.last().state, mbslam::status_t::STATE_STOPPING);
    EXPECT_TRUE(run.output.error.empty()) << run.output.error;
    EXPECT_EQ(run.output.poses, run.last().frames_processed) << "one logged pose per processed frame";
    EXPECT_EQ(static_cast<int64_t>(run.poses.size()), run.last().frames_processed);
    EXPECT_FALSE(run.summary_json.empty()) << "summary.json not written";
    report->survived = run.finished.ok() && !run.statuses.empty() && run.output.error.empty() &&
                       run.output.poses == run.last().frames_processed && !run.summary_json.empty();
    report->states_seen = run.States();
  }

  // Tracking must be established before the fault starts (else the fault proves nothing).
  static void ExpectTrackingBefore(const ServiceRun& run, int64_t fault_seq) {
    EXPECT_GE(fault_test::TrackedFraction(run.poses, fault_seq - 15, fault_seq), 0.8)
        << "tracking was not established before the fault at frame " << fault_seq;
  }

  // Frames to recover from the first processed frame with seq >= end_seq; asserted <= bound.
  static int ExpectRecovery(const ServiceRun& run, int64_t end_seq, int bound, FaultReport* report) {
    const size_t first = fault_test::FirstPoseAtOrAfter(run.poses, end_seq);
    EXPECT_LT(first, run.poses.size()) << "no frame processed after the fault";
    const int frames = fault_test::FramesToRecover(run.poses, first);
    report->frames_to_recover = frames;
    report->recovery_bound = bound;
    EXPECT_GE(frames, 0) << "tracking never recovered after frame " << end_seq;
    EXPECT_LE(frames, bound) << "tracking recovered only after " << frames << " frames";
    std::printf("%s: frames to recover %d (bound %d), states seen:", report->name.c_str(), frames, bound);
    for (const auto& s : report->states_seen) std::printf(" %s", s.c_str());
    std::printf("\n");
    return frames;
  }

  static LogEditor* base_;
  static std::string* setup_error_;
};

LogEditor* FaultInjection::base_ = nullptr;
std::string* FaultInjection::setup_error_ = nullptr;

// (b) 30 % of the frames dropped at random for 8 s (frames 45-164).
TEST_F(FaultInjection, RandomFrameDrops) {
  FaultReport report;
  report.name = "drop_30pct";
  LogEditor log = Base();
  const int dropped = log.DropFrames(0.3, 7, 45, 165);
  ASSERT_GT(dropped, 25);
  ASSERT_LT(dropped, 50);
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 45);
  // Every missing frame is reported as lost upstream (seq gaps), no more, no less.
  EXPECT_EQ(run.C("image_frames_lost_upstream"), dropped);
  EXPECT_EQ(run.last().frames_received, fault_test::kSequenceFrames - dropped);
  report.status_counter = {{"image_frames_lost_upstream", run.C("image_frames_lost_upstream")},
                           {"tracking_lost", run.C("tracking_lost")}};
  const double during = fault_test::TrackedFraction(run.poses, 45, 165);
  report.note = std::to_string(dropped) + " of 120 frames dropped; tracked during the drops " +
                std::to_string(static_cast<int>(std::lround(100 * during))) + " %";
  ExpectRecovery(run, 165, 15, &report);
  PrintFaultReport(report);
}

// (c) The shared sensor clock steps 5 s forwards at frame 90.
TEST_F(FaultInjection, TimeJumpForward) {
  FaultReport report;
  report.name = "time_jump_forward";
  LogEditor log = Base();
  ASSERT_TRUE(log.ShiftTime(90, Us(5.0)).ok());
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 90);
  EXPECT_EQ(run.C("image_time_jump"), 1);
  EXPECT_EQ(run.C("image_time_backwards"), 0);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames);
  report.status_counter = {{"image_time_jump", run.C("image_time_jump")},
                           {"odometry_gap", run.C("odometry_gap")}};
  report.note = "+5 s at frame 90 on every input";
  ExpectRecovery(run, 90, 15, &report);
  PrintFaultReport(report);
}

// (c) The clock steps 5 s back at frame 90 and stays there: the frames before
// input.time_reset_after_frames are rejected, then a new timeline starts (re-initialise).
TEST_F(FaultInjection, TimeJumpBackward) {
  FaultReport report;
  report.name = "time_jump_backward";
  LogEditor log = Base();
  ASSERT_TRUE(log.ShiftTime(90, -Us(5.0)).ok());
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 90);
  const int reset_after = InputOptions().time_reset_after_frames;
  EXPECT_EQ(run.C("image_time_backwards"), reset_after - 1);
  EXPECT_EQ(run.C("image_timeline_reset"), 1);
  // Only the odometry of the rejected stretch is refused; the new timeline's is taken.
  EXPECT_EQ(run.C("odometry_time_backwards"), reset_after - 1);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames - (reset_after - 1));
  report.status_counter = {{"image_time_backwards", run.C("image_time_backwards")},
                           {"image_timeline_reset", run.C("image_timeline_reset")},
                           {"odometry_time_backwards", run.C("odometry_time_backwards")}};
  report.note = "-5 s at frame 90; frames 90-" + std::to_string(90 + reset_after - 2) +
                " rejected, new timeline at frame " + std::to_string(90 + reset_after - 1);
  ExpectRecovery(run, 90 + reset_after - 1, 45, &report);
  PrintFaultReport(report);
}

// (d) No odometry for 10 s (frames 45-194), then back.
TEST_F(FaultInjection, OdometryMissingTenSeconds) {
  FaultReport report;
  report.name = "odometry_missing_10s";
  LogEditor log = Base();
  const int64_t from = log.FrameUtime(45);
  const int64_t to = from + Us(10.0);
  ASSERT_GT(log.DropOdometry(from, to), 140);
  // The images that should be reported: more than odometry_timeout_us after the
  // latest odometry before them in the log.
  int64_t expected_without = 0;
  {
    const ChannelOptions ch;
    int64_t last_odom = 0;
    for (const LcmLogEvent& e : log.events()) {
      int64_t t = 0;
      if (!fault::ReadMessageUtime(e.data, &t)) continue;
      if (e.channel == ch.odometry) last_odom = t;
      if (e.channel == ch.camera_image && last_odom != 0 && t - last_odom > InputOptions().odometry_timeout_us) {
        ++expected_without;
      }
    }
  }
  ASSERT_GT(expected_without, 130);
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 45);
  EXPECT_EQ(run.C("odometry_gap"), 1);
  EXPECT_EQ(run.C("image_without_odometry"), expected_without);
  // The status said so while it lasted.
  bool said = false;
  for (const auto& st : run.statuses) said |= st.message.find("image_without_odometry") != std::string::npos;
  EXPECT_TRUE(said) << "no PERCEPTION_STATUS message named the missing odometry";
  report.status_counter = {{"odometry_gap", run.C("odometry_gap")},
                           {"image_without_odometry", run.C("image_without_odometry")}};
  int first_back = 0;
  while (first_back < log.num_frames() && log.FrameUtime(first_back) < to) ++first_back;
  report.note = "odometry removed for 10 s from frame 45; back at frame " + std::to_string(first_back);
  ExpectRecovery(run, first_back, 15, &report);
  PrintFaultReport(report);
}

// (e) NaN and infinite odometry for 1 s each.
TEST_F(FaultInjection, NonFiniteOdometry) {
  FaultReport report;
  report.name = "nan_inf_odometry";
  LogEditor log = Base();
  const int nan_count = log.CorruptOdometry(log.FrameUtime(45), log.FrameUtime(60), kNan);
  const int inf_count = log.CorruptOdometry(log.FrameUtime(105), log.FrameUtime(120), kInf);
  ASSERT_EQ(nan_count, 15);
  ASSERT_EQ(inf_count, 15);
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 45);
  EXPECT_EQ(run.C("odometry_invalid"), nan_count + inf_count);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames);
  report.status_counter = {{"odometry_invalid", run.C("odometry_invalid")},
                           {"odometry_gap", run.C("odometry_gap")}};
  report.note = "15 NaN (frames 45-59) and 15 inf (frames 105-119) odometry messages";
  ExpectRecovery(run, 120, 5, &report);
  PrintFaultReport(report);
}

// (e) A calibration with NaN, then one with infinite values, among the good ones.
TEST_F(FaultInjection, NonFiniteCalibration) {
  FaultReport report;
  report.name = "nan_inf_calibration";
  LogEditor log = Base();
  ASSERT_TRUE(log.InjectBadCalibration(60, kNan).ok());
  ASSERT_TRUE(log.InjectBadCalibration(120, kInf).ok());
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 60);
  EXPECT_EQ(run.C("calibration_invalid"), 2);
  EXPECT_EQ(run.C("image_calibration_mismatch"), 0);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames);
  report.status_counter = {{"calibration_invalid", run.C("calibration_invalid")}};
  report.note = "NaN calibration before frame 60, inf before frame 120";
  ExpectRecovery(run, 60, 5, &report);
  PrintFaultReport(report);
}

// (f) One frame of another size (160x120 in a 320x240 stream) with a calibration.
TEST_F(FaultInjection, WrongSizeFrame) {
  FaultReport report;
  report.name = "wrong_size_frame";
  LogEditor log = Base();
  ASSERT_TRUE(log.ResizeFrame(90, 160, 120).ok());
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 90);
  EXPECT_EQ(run.C("image_calibration_mismatch"), 1);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames - 1);
  EXPECT_EQ(run.last().frames_rejected, 1);
  report.status_counter = {{"image_calibration_mismatch", run.C("image_calibration_mismatch")}};
  report.note = "frame 90 at 160x120, calibration 320x240";
  ExpectRecovery(run, 91, 5, &report);
  PrintFaultReport(report);
}

// (f) The same without any calibration (approximate intrinsics): the odd frame must
// not reach the tracker as a new image size.
TEST_F(FaultInjection, WrongSizeFrameUncalibrated) {
  FaultReport report;
  report.name = "wrong_size_frame_uncalibrated";
  LogEditor log = Base();
  ASSERT_GT(log.DropChannel(ChannelOptions().camera_calibration), 0);
  ASSERT_TRUE(log.ResizeFrame(90, 160, 120).ok());
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 90);
  EXPECT_EQ(run.C("image_size_changed"), 1);
  EXPECT_EQ(run.C("image_timeline_reset"), 0);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames - 1);
  report.status_counter = {{"image_size_changed", run.C("image_size_changed")}};
  report.note = "frame 90 at 160x120, no calibration (approximate intrinsics)";
  ExpectRecovery(run, 91, 5, &report);
  PrintFaultReport(report);
}

// (f) The image size changes for good (uncalibrated camera switched to 160x120 at
// frame 120): the first frames are rejected as strays, then a new timeline starts.
TEST_F(FaultInjection, LastingSizeChange) {
  FaultReport report;
  report.name = "size_change_for_good";
  LogEditor log = Base();
  ASSERT_GT(log.DropChannel(ChannelOptions().camera_calibration), 0);
  for (int k = 120; k < log.num_frames(); ++k) ASSERT_TRUE(log.ResizeFrame(k, 160, 120).ok());
  const ServiceRun run = Run(log);
  ExpectSurvived(run, &report);
  ExpectTrackingBefore(run, 120);
  const int reset_after = InputOptions().time_reset_after_frames;
  EXPECT_EQ(run.C("image_size_changed"), reset_after);
  EXPECT_EQ(run.C("image_timeline_reset"), 1);
  EXPECT_EQ(run.last().frames_processed, fault_test::kSequenceFrames - (reset_after - 1));
  report.status_counter = {{"image_size_changed", run.C("image_size_changed")},
                           {"image_timeline_reset", run.C("image_timeline_reset")}};
  report.note = "every frame from 120 on at 160x120, no calibration; new timeline at frame " +
                std::to_string(120 + reset_after - 1);
  ExpectRecovery(run, 120 + reset_after - 1, 45, &report);
  PrintFaultReport(report);
}

// (g) Realtime mode, replayed at 4x (60 frames/s): frames 60-104 are held back and then
// delivered at 5x that rate (300 frames/s, faster than the service processes 320x240
// images, so the burst overruns it; at 2x a faster pipeline kept up with most of it).
// The stale ones are dropped and counted, nothing is lost silently, latency stays bounded.
TEST_F(FaultInjection, BurstAtFiveTimesTheFrameRate) {
  FaultReport report;
  report.name = "burst_5x";
  LogEditor log = Base();
  log.Truncate(150);
  ASSERT_TRUE(log.Burst(60, 45, 5.0).ok());
  const ServiceRun run = Run(log, /*realtime=*/true, /*speed=*/4.0);
  ExpectSurvived(run, &report);
  const mbslam::status_t& last = run.last();
  EXPECT_EQ(last.frames_received, 150);
  EXPECT_EQ(last.frames_received, last.frames_processed + last.frames_dropped)
      << "every frame received is processed or counted as dropped";
  EXPECT_EQ(run.C("image_dropped_stale"), last.frames_dropped);
  int processed_in_burst = 0;
  for (const auto& p : run.poses) processed_in_burst += p.frame_seq >= 60 && p.frame_seq < 105;
  const int dropped_in_burst = 45 - processed_in_burst;
  EXPECT_GE(dropped_in_burst, 10) << "the burst did not overrun the pipeline";
  EXPECT_GE(last.frames_dropped, dropped_in_burst);
  double worst_p99 = 0.0;
  for (const auto& st : run.statuses) worst_p99 = std::max(worst_p99, st.latency_p99_ms);
  EXPECT_LT(worst_p99, 1500.0) << "latency grew with the burst";
  report.status_counter = {{"image_dropped_stale", run.C("image_dropped_stale")},
                           {"frames_dropped", last.frames_dropped}};
  report.note = std::to_string(dropped_in_burst) + " of the 45 burst frames dropped as stale; worst latency p99 " +
                std::to_string(static_cast<int>(worst_p99)) + " ms";
  ExpectRecovery(run, 105, 30, &report);
  PrintFaultReport(report);
}

}  // namespace
}  // namespace mbslam
