// The `viewer` executable on file:// logs written by the test: PNG snapshots appear,
// decode, and show more than an empty scene; bad messages in the log are counted, not
// fatal; SIGTERM ends it cleanly with final snapshots; the command line is checked.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "common/lcm/lcm_log.h"
#include "common/util/atomic_file.h"
#include "mbslam/camera_pose_t.hpp"
#include "viewer/testing/synthetic_outputs.h"

namespace mbslam {
namespace viewer {
namespace {

std::string ViewerBinary() {
  const char* dir = std::getenv("MBSLAM_BIN_DIR");
  if (dir && *dir) return std::string(dir) + "/viewer";
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  std::string path = n > 0 ? std::string(self, static_cast<size_t>(n)) : std::string();
  path = path.substr(0, path.rfind('/'));  // <build>/tests
  return path.substr(0, path.rfind('/')) + "/bin/viewer";
}

std::string TempDir(const std::string& name) {
  const std::string dir =
      std::string(::testing::TempDir()) + "viewer_cli_" + name + "_" + std::to_string(::getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

struct Result {
  int exit_code = -1;
  std::string out, err;
};

// Runs the viewer with stdout / stderr in files; `signal_after_ms` >= 0 sends SIGTERM then.
Result RunViewer(const std::vector<std::string>& args, const std::string& dir,
                 int signal_after_ms = -1, double timeout_s = 60.0) {
  const std::string out_path = dir + "/stdout.txt", err_path = dir + "/stderr.txt";
  const pid_t pid = fork();
  if (pid == 0) {
    if (!freopen(out_path.c_str(), "w", stdout) || !freopen(err_path.c_str(), "w", stderr))
      _exit(126);
    std::vector<std::string> all = {ViewerBinary()};
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  Result result;
  int status = 0;
  const auto start = std::chrono::steady_clock::now();
  bool signalled = false, done = false;
  while (!done) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (waitpid(pid, &status, WNOHANG) == pid) {
      done = true;
      break;
    }
    if (signal_after_ms >= 0 && !signalled && elapsed * 1000.0 >= signal_after_ms) {
      kill(pid, SIGTERM);
      signalled = true;
    }
    if (elapsed > timeout_s) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (done && WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  ReadFileToString(out_path, &result.out);
  ReadFileToString(err_path, &result.err);
  return result;
}

// Mean absolute difference of two images of the same size (grey levels).
double MeanDifference(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat diff;
  cv::absdiff(a, b, diff);
  const cv::Scalar m = cv::mean(diff);
  return (m[0] + m[1] + m[2]) / 3.0;
}

int CountPngs(const std::string& dir, const std::string& prefix) {
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && e.path().extension() == ".png" &&
        name.find("latest") == std::string::npos) {
      ++n;
    }
  }
  return n;
}

TEST(ViewerCli, RendersALogWithBadMessagesDeterministically) {
  const std::string dir = TempDir("log");
  testing::SyntheticOptions synthetic;
  synthetic.frames = 30;  // 3 s at 10 Hz
  synthetic.jpeg = true;
  int bad = 0;
  const std::string log = dir + "/outputs.lcmlog";
  ASSERT_TRUE(
      testing::WriteSyntheticLog(log, synthetic, ChannelOptions(), /*faults=*/true, &bad).ok());
  ASSERT_EQ(bad, 5);

  // An "empty" log: one pose before tracking started, nothing else.
  const std::string empty_log = dir + "/empty.lcmlog";
  {
    Status s;
    auto writer = LcmLogWriter::Open(empty_log, &s);
    ASSERT_TRUE(writer) << s.message();
    mbslam::camera_pose_t pose{};
    pose.utime = 1000000;
    pose.orientation[0] = 1.0;
    ASSERT_TRUE(writer->Write("PERCEPTION_CAMERA_POSE", pose.utime, pose).ok());
    writer->Flush();
  }

  const std::vector<std::string> common = {
      "--config", "config/viewer.yaml", "--set", "view3d.width=640",
      "--set",    "view3d.height=360",  "--set", "viewer.snapshot_period_s=1.0"};
  auto args = [&](const std::string& log_path, const std::string& out) {
    std::vector<std::string> a = common;
    a.insert(a.end(), {"--lcm-url", "file://" + log_path + "?speed=0", "--out", out});
    return a;
  };
  const Result run = RunViewer(args(log, dir + "/out"), dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Result empty = RunViewer(args(empty_log, dir + "/empty_out"), dir);
  ASSERT_EQ(empty.exit_code, 0) << empty.err;

  // Periodic snapshots at 1 s and 2 s of message time, plus the final one.
  EXPECT_EQ(CountPngs(dir + "/out", "view3d_"), 3);
  EXPECT_EQ(CountPngs(dir + "/out", "image_"), 3);
  for (const char* view : {"view3d", "image"}) {
    const cv::Mat img = cv::imread(dir + "/out/" + view + "_latest.png", cv::IMREAD_COLOR);
    const cv::Mat blank = cv::imread(dir + "/empty_out/" + view + "_latest.png", cv::IMREAD_COLOR);
    ASSERT_FALSE(img.empty()) << view;
    ASSERT_FALSE(blank.empty()) << view;
    if (std::string(view) == "view3d") {
      EXPECT_EQ(img.size(), cv::Size(640, 360));
      ASSERT_EQ(blank.size(), img.size());
      EXPECT_GT(MeanDifference(img, blank), 5.0) << "the 3D view looks empty";
    } else {
      EXPECT_EQ(img.cols, 640);  // the 640x480 camera image at scale 1, plus legend bands
      EXPECT_GT(img.rows, 480);
      // The empty run has no image: a grey canvas of another size, or none at all.
      cv::Mat gray;
      cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
      cv::Scalar mean, stddev;
      cv::meanStdDev(gray, mean, stddev);
      EXPECT_GT(stddev[0], 20.0) << "the image view looks flat";
    }
  }
  std::string stats;
  ASSERT_TRUE(ReadFileToString(dir + "/out/viewer_stats.json", &stats).ok());
  EXPECT_NE(stats.find("\"bad_messages_total\": 5"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"image_decode_errors\": 0"), std::string::npos) << stats;
  EXPECT_NE(stats.find("\"render_errors\": 0"), std::string::npos) << stats;
  EXPECT_NE(run.err.find("bad message"), std::string::npos);

  // A second replay gives the same pictures (message time, not wall time).
  const Result again = RunViewer(args(log, dir + "/again"), dir);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/out")) {
    if (e.path().extension() != ".png") continue;
    const cv::Mat a = cv::imread(e.path().string());
    const cv::Mat b = cv::imread(dir + "/again/" + e.path().filename().string());
    ASSERT_FALSE(b.empty()) << e.path();
    EXPECT_EQ(MeanDifference(a, b), 0.0) << e.path();
  }
  std::filesystem::remove_all(dir);
}

TEST(ViewerCli, SigtermEndsCleanlyWithFinalSnapshots) {
  const std::string dir = TempDir("sigterm");
  testing::SyntheticOptions synthetic;
  synthetic.frames = 8;
  synthetic.width = 320;
  synthetic.height = 240;
  const std::string log = dir + "/outputs.lcmlog";
  ASSERT_TRUE(testing::WriteSyntheticLog(log, synthetic, ChannelOptions(), false, nullptr).ok());
  // Stays after the end of the log until a signal; no periodic snapshots.
  const Result run =
      RunViewer({"--lcm-url", "file://" + log + "?speed=0", "--out", dir + "/out", "--set",
                 "viewer.exit_at_end_of_log=false", "--set", "viewer.snapshot_period_s=0", "--set",
                 "view3d.width=320", "--set", "view3d.height=240"},
                dir, /*signal_after_ms=*/1500);
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("on signal"), std::string::npos) << run.err;
  EXPECT_EQ(CountPngs(dir + "/out", "view3d_"), 1);
  EXPECT_EQ(CountPngs(dir + "/out", "image_"), 1);
  EXPECT_TRUE(std::filesystem::exists(dir + "/out/viewer_stats.json"));
  std::filesystem::remove_all(dir);
}

TEST(ViewerCli, PrintConfigMatchesTheConfigFileAndBadArgumentsFail) {
  const std::string dir = TempDir("args");
  const Result print = RunViewer({"--print-config"}, dir);
  ASSERT_EQ(print.exit_code, 0) << print.err;
  std::string file;
  ASSERT_TRUE(ReadFileToString("config/viewer.yaml", &file).ok()) << "run from the repository root";
  EXPECT_EQ(print.out, file) << "regenerate config/viewer.yaml with viewer --print-config";

  const Result set = RunViewer({"--set", "view3d.camera_mode=top_down", "--print-config"}, dir);
  ASSERT_EQ(set.exit_code, 0) << set.err;
  EXPECT_NE(set.out.find("camera_mode: \"top_down\""), std::string::npos);

  EXPECT_EQ(RunViewer({"--set", "view3d.camera_mode=orbit", "--print-config"}, dir).exit_code, 2);
  EXPECT_EQ(RunViewer({"--set", "view3d.no_such_option=1"}, dir).exit_code, 2);
  EXPECT_EQ(RunViewer({"--bogus"}, dir).exit_code, 2);
  EXPECT_EQ(RunViewer({"--config", dir + "/missing.yaml"}, dir).exit_code, 2);
  EXPECT_EQ(RunViewer({"--lcm-url"}, dir).exit_code, 2);
  // A log that does not exist: LCM cannot open it.
  EXPECT_EQ(
      RunViewer({"--lcm-url", "file://" + dir + "/none.lcmlog?speed=0", "--out", dir + "/o"}, dir)
          .exit_code,
      3);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace viewer
}  // namespace mbslam
