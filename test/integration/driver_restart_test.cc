// (a) The camera driver is killed (SIGKILL) mid-stream and restarted while
// perception_service runs live. Processes talk over udpm://, so this runs ONLY inside
// a private network namespace (CTest: test/netns/run_in_netns.sh).
//
// camera_driver plays the simulated sequence (15 Hz) at 2x; after frame 80 it is
// killed; 3 s later a new driver starts 30 frames further on (the camera kept running:
// time jumps 2 s forward, seq restarts at 0). The service must stay up, report the
// outage (STALLED) and the restart (image_seq_restart, image_time_jump), track again
// within the stated number of frames, exit cleanly on SIGTERM and leave a decodable
// output log.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <fstream>
#include <functional>
#include <mutex>
#include <set>
#include <thread>

#include "common/lcm/lcm_bus.h"
#include "common/util/time.h"
#include "test/integration/fault_test_util.h"

namespace mbslam {
namespace {

using fault_test::FaultReport;

constexpr char kUrl[] = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304";

// A child process we can poll, signal and reap (stdout/stderr to files).
class Child {
 public:
  Child(const std::vector<std::string>& argv, const std::string& log_path) {
    pid_ = fork();
    if (pid_ == 0) {
      const int fd = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd >= 0) {
        dup2(fd, STDOUT_FILENO);
        dup2(fd, STDERR_FILENO);
      }
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
  }
  ~Child() {
    if (running()) {
      kill(pid_, SIGKILL);
      Wait(5.0);
    }
  }
  bool running() {
    if (exited_) return false;
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) Reap(status);
    return !exited_;
  }
  void Signal(int sig) { kill(pid_, sig); }
  // Exit code, -1 if killed by a signal or still running after timeout_s.
  int Wait(double timeout_s) {
    const int64_t until = MonotonicUtime() + SecondsToUtime(timeout_s);
    while (running() && MonotonicUtime() < until) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    return exited_ ? exit_code_ : -1;
  }

 private:
  void Reap(int status) {
    exited_ = true;
    exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
  pid_t pid_ = -1;
  bool exited_ = false;
  int exit_code_ = -1;
};

// Only loopback may be visible: udpm must never leave a private namespace.
bool OnlyLoopback() {
  std::ifstream dev("/proc/net/dev");
  std::string line;
  int interfaces = 0;
  bool other = false;
  while (std::getline(dev, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string name = line.substr(0, colon);
    name.erase(0, name.find_first_not_of(' '));
    ++interfaces;
    other |= name != "lo";
  }
  return interfaces > 0 && !other;
}

struct Received {
  std::mutex mutex;
  std::vector<std::pair<int64_t, mbslam::status_t>> statuses;  // (wall time, message)
  std::vector<std::pair<int64_t, mbslam::camera_pose_t>> poses;
};

TEST(DriverRestart, ServiceSurvivesAKilledAndRestartedCameraDriver) {
  if (!OnlyLoopback()) GTEST_SKIP() << "not inside a private network namespace (test/netns/run_in_netns.sh)";
  std::string error;
  const std::string seq = fault_test::EnsureSequence(&error);
  ASSERT_FALSE(seq.empty()) << error;
  const std::string work = testing_util::MakeTestTempDir("driver_restart");
  ASSERT_FALSE(work.empty());

  Status s;
  std::unique_ptr<LcmBus> bus = LcmBus::Create(kUrl, &s);
  ASSERT_TRUE(bus) << s.message();
  const ChannelOptions ch;
  Received rx;
  bus->Subscribe(ch.perception_status, [&rx](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::status_t m{};
    if (!DecodeLcmMessage(d, n, &m).ok()) return;
    std::lock_guard<std::mutex> lock(rx.mutex);
    rx.statuses.emplace_back(MonotonicUtime(), std::move(m));
  }, 10000);
  bus->Subscribe(ch.perception_camera_pose, [&rx](const std::string&, const uint8_t* d, size_t n, int64_t) {
    mbslam::camera_pose_t m{};
    if (!DecodeLcmMessage(d, n, &m).ok()) return;
    std::lock_guard<std::mutex> lock(rx.mutex);
    rx.poses.emplace_back(MonotonicUtime(), m);
  }, 10000);
  std::atomic<bool> stop{false};
  std::thread listener([&] {
    while (!stop) bus->HandleTimeout(50);
  });
  auto wait_for = [&](double timeout_s, const std::function<bool()>& done) {
    const int64_t until = MonotonicUtime() + SecondsToUtime(timeout_s);
    while (MonotonicUtime() < until) {
      {
        std::lock_guard<std::mutex> lock(rx.mutex);
        if (done()) return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return false;
  };

  Child service({testing_util::BinPath("perception_service"), "--lcm-url", kUrl, "--mode", "realtime",
                 "--output-log", work + "/out.lcmlog", "--output-dir", work + "/result"},
                work + "/service.log");
  ASSERT_TRUE(wait_for(15.0, [&] { return !rx.statuses.empty(); })) << "the service published no status";

  const std::vector<std::string> driver = {testing_util::BinPath("camera_driver"), "--source", "sequence",
                                           "--input", seq, "--lcm-url", kUrl, "--speed", "2", "--no-progress",
                                           "--quiet"};
  Child first(driver, work + "/driver1.log");
  int64_t last_seq = -1;
  ASSERT_TRUE(wait_for(60.0, [&] {
    if (rx.poses.empty()) return false;
    last_seq = rx.poses.back().second.frame_seq;
    return last_seq >= 80;
  })) << "no pose for frame 80";
  first.Signal(SIGKILL);
  const int64_t killed_at = MonotonicUtime();
  EXPECT_EQ(first.Wait(5.0), -1) << "killed by the signal";

  // The outage: nothing arrives, the service must say so and stay up.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  ASSERT_TRUE(service.running()) << "perception_service died when its camera driver was killed";
  size_t poses_before_restart = 0;
  int64_t seq_at_kill = 0;
  {
    std::lock_guard<std::mutex> lock(rx.mutex);
    poses_before_restart = rx.poses.size();
    seq_at_kill = rx.poses.back().second.frame_seq;
  }
  const int64_t restart_frame = seq_at_kill + 30;
  const int64_t restarted_at = MonotonicUtime();
  std::vector<std::string> second_args = driver;
  second_args.insert(second_args.end(), {"--start-frame", std::to_string(restart_frame)});
  Child second(second_args, work + "/driver2.log");
  EXPECT_EQ(second.Wait(60.0), 0) << testing_util::ReadWholeFile(work + "/driver2.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the last frames through the pipeline
  ASSERT_TRUE(service.running()) << "perception_service died after the restart";
  service.Signal(SIGTERM);
  const int service_exit = service.Wait(30.0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the final status over udpm
  stop = true;
  listener.join();

  FaultReport report;
  report.name = "driver_restart";
  EXPECT_EQ(service_exit, 0) << testing_util::ReadWholeFile(work + "/service.log");

  // The outage was reported as STALLED, the restart by its counters.
  bool stalled = false;
  std::set<std::string> states;
  for (const auto& [t, st] : rx.statuses) {
    states.insert(fault_test::StateName(st.state));
    stalled |= t > killed_at && t < restarted_at && st.state == mbslam::status_t::STATE_STALLED;
  }
  report.states_seen.assign(states.begin(), states.end());
  EXPECT_TRUE(stalled) << "no STALLED status during the outage";
  ASSERT_FALSE(rx.statuses.empty());
  const mbslam::status_t& final_status = rx.statuses.back().second;
  EXPECT_EQ(final_status.state, mbslam::status_t::STATE_STOPPING) << "the final status did not arrive";
  auto counters = fault_test::Counters(final_status);
  EXPECT_EQ(counters["image_seq_restart"], 1);
  EXPECT_EQ(counters["image_time_jump"], 1);
  report.status_counter = {{"image_seq_restart", counters["image_seq_restart"]},
                           {"image_time_jump", counters["image_time_jump"]},
                           {"image_dropped_stale", counters["image_dropped_stale"]}};

  // Tracking before the kill and after the restart.
  std::vector<mbslam::camera_pose_t> poses;
  for (const auto& [t, p] : rx.poses) poses.push_back(p);
  ASSERT_GT(poses.size(), poses_before_restart) << "no pose after the restart";
  EXPECT_GE(fault_test::TrackedFraction(poses, seq_at_kill - 20, seq_at_kill + 1), 0.8)
      << "not tracking before the kill";
  const int recover = fault_test::FramesToRecover(poses, poses_before_restart);
  report.frames_to_recover = recover;
  report.recovery_bound = 45;
  EXPECT_GE(recover, 0) << "tracking never came back after the restart";
  EXPECT_LE(recover, report.recovery_bound);

  // Outputs: decodable log, one pose per processed frame, files written on SIGTERM.
  const fault_test::OutputLogCheck out = fault_test::CheckOutputLog(work + "/out.lcmlog");
  EXPECT_TRUE(out.error.empty()) << out.error;
  EXPECT_EQ(out.poses, final_status.frames_processed);
  EXPECT_TRUE(fault_test::FileExists(work + "/result/summary.json"));
  EXPECT_TRUE(fault_test::FileExists(work + "/result/camera_trajectory.tum"));
  report.survived = service_exit == 0 && out.error.empty() && stalled;
  report.note = "killed after frame " + std::to_string(seq_at_kill) + ", restarted 3 s later at frame " +
                std::to_string(restart_frame) + "; " + std::to_string(final_status.frames_processed) +
                " frames processed";
  std::printf("driver_restart: frames to recover %d (bound %d)\n", recover, report.recovery_bound);
  fault_test::PrintFaultReport(report);
}

}  // namespace
}  // namespace mbslam
