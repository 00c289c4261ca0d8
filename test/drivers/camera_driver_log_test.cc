// camera_driver end to end: datasets become LCM logs whose frames decode back
// bit-identical with the right timestamps; missing cameras fail with one line and a
// distinct exit code.

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/util/time.h"
#include "drivers/camera/camera_messages.h"
#include "drivers/camera/camera_test_util.h"
#include "drivers/common/exit_codes.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/image_t.hpp"
#include "test/drivers/process_util.h"

namespace mbslam {
namespace {

namespace fs = std::filesystem;
using testing_util::BinPath;
using testing_util::MakeTempDir;
using testing_util::MakeTestImage;
using testing_util::RunProcess;
using testing_util::WriteTextFile;

struct DecodedLog {
  std::vector<mbslam::image_t> images;
  std::vector<int64_t> image_event_times;
  std::vector<mbslam::camera_calibration_t> calibrations;
  std::vector<mbslam::ground_truth_t> truth;
  std::vector<std::string> channels;  // event order
};

DecodedLog ReadLog(const std::string& path) {
  DecodedLog log;
  std::vector<LcmLogEvent> events;
  EXPECT_TRUE(ReadLcmLog(path, &events).ok());
  for (const LcmLogEvent& e : events) {
    log.channels.push_back(e.channel);
    if (e.channel == "CAMERA_IMAGE") {
      mbslam::image_t m{};
      EXPECT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
      EXPECT_EQ(e.timestamp, m.utime);
      log.images.push_back(m);
      log.image_event_times.push_back(e.timestamp);
    } else if (e.channel == "CAMERA_CALIBRATION") {
      mbslam::camera_calibration_t m{};
      EXPECT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
      log.calibrations.push_back(m);
    } else if (e.channel == "GROUND_TRUTH") {
      mbslam::ground_truth_t m{};
      EXPECT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
      log.truth.push_back(m);
    } else {
      ADD_FAILURE() << "unexpected channel " << e.channel;
    }
  }
  return log;
}

cv::Mat Decode(const mbslam::image_t& msg) {
  cv::Mat image;
  const Status st = DecodeImageMessage(msg, &image);
  EXPECT_TRUE(st.ok()) << st.message();
  return image;
}

bool Identical(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

testing_util::ProcessResult RunDriver(std::vector<std::string> args) {
  args.insert(args.begin(), BinPath("camera_driver"));
  args.push_back("--quiet");
  args.push_back("--no-progress");
  return RunProcess(args);
}

int CountLines(const std::string& text) {
  int n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

TEST(CameraDriverLog, ImageFolderBecomesALogOfIdenticalFrames) {
  const std::string dir = MakeTempDir("it_folder");
  fs::create_directories(dir + "/images");
  std::vector<std::string> files;
  for (int i = 0; i < 12; ++i) {
    files.push_back(dir + "/images/img" + std::to_string(i) + (i % 3 == 0 ? ".jpg" : ".png"));
    cv::imwrite(files.back(), MakeTestImage(40, 30, i % 2 ? 1 : 3, i));
  }
  const std::string log = dir + "/out.lcmlog";
  const auto r = RunDriver({"--source", "folder", "--input", dir + "/images", "--rate", "7.5",
                            "--set", "folder.time_origin_s=100", "--log", log});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  const DecodedLog decoded = ReadLog(log);
  ASSERT_EQ(decoded.images.size(), files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    const cv::Mat original = cv::imread(files[i], cv::IMREAD_UNCHANGED);
    EXPECT_TRUE(Identical(Decode(decoded.images[i]), original)) << files[i];
    EXPECT_EQ(decoded.images[i].utime, 100000000 + std::llround(static_cast<double>(i) * 1e6 / 7.5));
    EXPECT_EQ(decoded.images[i].seq, static_cast<int64_t>(i));
  }
  ASSERT_FALSE(decoded.calibrations.empty());
  EXPECT_EQ(decoded.channels.front(), "CAMERA_CALIBRATION");
  EXPECT_EQ(decoded.calibrations[0].width, 40);
  EXPECT_TRUE(decoded.truth.empty());

  // "source" encoding: the messages carry the files' own bytes.
  const std::string log2 = dir + "/source.lcmlog";
  ASSERT_EQ(RunDriver({"--source", "folder", "--input", dir + "/images", "--encoding", "source",
                       "--log", log2}).exit_code, kExitOk);
  const DecodedLog passthrough = ReadLog(log2);
  ASSERT_EQ(passthrough.images.size(), files.size());
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string bytes = testing_util::ReadWholeFile(files[i]);
    EXPECT_EQ(std::string(passthrough.images[i].data.begin(), passthrough.images[i].data.end()), bytes);
  }
}

TEST(CameraDriverLog, LogsAreDeterministic) {
  const std::string dir = MakeTempDir("it_determ");
  for (int i = 0; i < 5; ++i) cv::imwrite(dir + "/" + std::to_string(i) + ".png", MakeTestImage(16, 16, 3, i));
  ASSERT_EQ(RunDriver({"--input", dir, "--log", dir + "/a.lcmlog"}).exit_code, kExitOk);
  ASSERT_EQ(RunDriver({"--input", dir, "--log", dir + "/b.lcmlog"}).exit_code, kExitOk);
  EXPECT_EQ(testing_util::ReadWholeFile(dir + "/a.lcmlog"), testing_util::ReadWholeFile(dir + "/b.lcmlog"));
}

TEST(CameraDriverLog, VideoBecomesALogOfIdenticalFrames) {
  const std::string dir = MakeTempDir("it_video");
  const std::string video = dir + "/clip.avi";
  std::vector<cv::Mat> written;
  {
    cv::VideoWriter writer(video, cv::CAP_FFMPEG, cv::VideoWriter::fourcc('F', 'F', 'V', '1'), 20.0,
                           cv::Size(64, 48), true);
    ASSERT_TRUE(writer.isOpened());
    for (int i = 0; i < 15; ++i) {
      written.push_back(MakeTestImage(64, 48, 3, i));
      writer.write(written.back());
    }
  }
  std::vector<cv::Mat> reference;
  cv::VideoCapture cap(video, cv::CAP_FFMPEG);
  for (cv::Mat m; cap.read(m);) reference.push_back(m.clone());
  ASSERT_EQ(reference.size(), written.size());
  const std::string log = dir + "/out.lcmlog";
  const auto r = RunDriver({"--source", "video", "--input", video, "--log", log});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  const DecodedLog decoded = ReadLog(log);
  ASSERT_EQ(decoded.images.size(), reference.size());
  for (size_t i = 0; i < reference.size(); ++i) {
    const cv::Mat frame = Decode(decoded.images[i]);
    EXPECT_TRUE(Identical(frame, reference[i])) << i;  // what the decoder gives
    EXPECT_TRUE(Identical(frame, written[i])) << i;    // FFV1 is lossless: what was written
    EXPECT_EQ(decoded.images[i].utime, 50000 * static_cast<int64_t>(i));
  }
  // A range of the video.
  const std::string part = dir + "/part.lcmlog";
  ASSERT_EQ(RunDriver({"--source", "video", "--input", video, "--start-frame", "5", "--end-frame",
                       "9", "--log", part}).exit_code, kExitOk);
  const DecodedLog range = ReadLog(part);
  ASSERT_EQ(range.images.size(), 4u);
  EXPECT_EQ(range.images[0].utime, 250000);
  EXPECT_TRUE(Identical(Decode(range.images[0]), reference[5]));
}

TEST(CameraDriverLog, TumSequenceBecomesALogWithTruth) {
  const std::string dir = MakeTempDir("it_tum");
  fs::create_directories(dir + "/rgb");
  const std::vector<std::string> stamps = {"1305031102.175304", "1305031102.211214",
                                           "1305031102.243211", "1305031102.275326"};
  std::string rgb = "# color images\n# timestamp filename\n";
  std::vector<cv::Mat> images;
  for (size_t i = 0; i < stamps.size(); ++i) {
    rgb += stamps[i] + " rgb/" + stamps[i] + ".png\n";
    images.push_back(MakeTestImage(32, 24, 3, static_cast<int>(i)));
    cv::imwrite(dir + "/rgb/" + stamps[i] + ".png", images.back());
  }
  WriteTextFile(dir + "/rgb.txt", rgb);
  std::string truth = "# timestamp tx ty tz qx qy qz qw\n";
  for (int i = 0; i <= 30; ++i) {
    char line[128];
    std::snprintf(line, sizeof(line), "%.4f %.4f 2 3 0 0 0 1\n", 1305031102.15 + 0.005 * i, 0.005 * i);
    truth += line;
  }
  WriteTextFile(dir + "/groundtruth.txt", truth);
  WriteTextFile(dir + "/calib.yaml",
                "camera_name: tum_test\nimage_width: 32\nimage_height: 24\n"
                "camera_matrix: {rows: 3, cols: 3, data: [30, 0, 16, 0, 31, 12, 0, 0, 1]}\n");
  const std::string log = dir + "/out.lcmlog";
  const auto r = RunDriver({"--source", "tum", "--input", dir, "--calibration", dir + "/calib.yaml",
                            "--log", log});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  const DecodedLog decoded = ReadLog(log);
  ASSERT_EQ(decoded.images.size(), 4u);
  ASSERT_EQ(decoded.truth.size(), 4u);
  const int64_t expected[] = {1305031102175304, 1305031102211214, 1305031102243211, 1305031102275326};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_TRUE(Identical(Decode(decoded.images[i]), images[i]));
    EXPECT_EQ(decoded.images[i].utime, expected[i]);
    EXPECT_EQ(decoded.images[i].camera_name, "tum_test");
    EXPECT_EQ(decoded.truth[i].utime, expected[i]);
    EXPECT_EQ(decoded.truth[i].frame_seq, static_cast<int64_t>(i));
    EXPECT_EQ(decoded.truth[i].source, "tum");
    ASSERT_EQ(decoded.truth[i].has_camera, 1);
    EXPECT_NEAR(decoded.truth[i].cam_position[0], static_cast<double>(expected[i] - 1305031102150000) * 1e-6, 1e-9);
    EXPECT_EQ(decoded.truth[i].cam_orientation[0], 1.0);  // w first
  }
  EXPECT_EQ(decoded.calibrations[0].fx, 30.0);
  EXPECT_EQ(decoded.calibrations[0].fy, 31.0);
}

TEST(CameraDriverLog, SimulatorSequenceBecomesALogWithTruth) {
  const std::string dir = MakeTempDir("it_seq") + "/seq";
  testing_util::WriteSimSequence(dir, 8);
  const std::string log = fs::path(dir).parent_path().string() + "/out.lcmlog";
  const auto r = RunDriver({"--source", "sequence", "--input", dir, "--log", log});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  const DecodedLog decoded = ReadLog(log);
  ASSERT_EQ(decoded.images.size(), 8u);
  ASSERT_EQ(decoded.truth.size(), 8u);
  for (int i = 0; i < 8; ++i) {
    const size_t k = static_cast<size_t>(i);
    const cv::Mat original = cv::imread(dir + "/images/" + testing_util::FrameName(i, ".png"), cv::IMREAD_UNCHANGED);
    EXPECT_TRUE(Identical(Decode(decoded.images[k]), original)) << i;
    EXPECT_EQ(decoded.images[k].utime, 1000000 + 50000 * i);
    EXPECT_EQ(decoded.images[k].camera_name, "sim_cam");  // from the sequence's calibration.yaml
    EXPECT_EQ(decoded.truth[k].source, "sim:unit_test_street");
    EXPECT_NEAR(decoded.truth[k].cam_position[0], 0.05 * i, 1e-12);
    ASSERT_EQ(decoded.truth[k].num_bodies, 1);
    EXPECT_EQ(decoded.truth[k].bodies[0].name, "car");
    EXPECT_EQ(decoded.truth[k].bodies[0].visible, i % 2 == 0 ? 1 : 0);
  }
  EXPECT_EQ(decoded.calibrations[0].fx, 50.0);
}

TEST(CameraDriverLog, MissingCamerasFailWithOneLineAndDistinctCodes) {
  bool any_fw = false, any_video = false;
  std::error_code ec;
  for (fs::directory_iterator it("/dev", ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    any_fw |= name.rfind("fw", 0) == 0;
    any_video |= name.rfind("video", 0) == 0;
  }
  if (!any_fw) {
    const auto r = RunDriver({"--source", "dc1394"});
    EXPECT_EQ(r.exit_code, kExitNoCamera);
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("no IEEE 1394 camera"), std::string::npos) << r.err;
  }
  if (!any_video) {
    const auto r = RunDriver({"--source", "v4l2"});
    EXPECT_EQ(r.exit_code, kExitNoCamera);
    EXPECT_EQ(CountLines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("/dev/video0 does not exist"), std::string::npos) << r.err;
  }
  const auto r = RunDriver({"--source", "v4l2", "--device", "/dev/video_absent_for_test"});
  EXPECT_EQ(r.exit_code, kExitNoCamera);
  EXPECT_EQ(CountLines(r.err), 1) << r.err;
  // The same failure with a reconnect loop that gives up.
  const auto retry = RunDriver({"--source", "v4l2", "--device", "/dev/video_absent_for_test",
                                "--reconnect", "--set", "live.max_reconnect_attempts=2", "--set",
                                "live.reconnect_interval_s=0.05"});
  EXPECT_EQ(retry.exit_code, kExitNoCamera);
  const auto mode = RunDriver({"--source", "dc1394", "--mode", "123x45_MONO8"});
  EXPECT_EQ(mode.exit_code, kExitUsage);
}

TEST(CameraDriverLog, BadInputsGiveDistinctCodes) {
  const std::string dir = MakeTempDir("it_bad");
  EXPECT_EQ(RunDriver({"--input", dir + "/missing", "--log", dir + "/x.lcmlog"}).exit_code,
            kExitInputNotFound);
  EXPECT_FALSE(fs::exists(dir + "/x.lcmlog"));  // no empty log left behind
  EXPECT_EQ(RunDriver({"--source", "webcam"}).exit_code, kExitUsage);
  EXPECT_EQ(RunDriver({"--bogus-flag"}).exit_code, kExitUsage);
  EXPECT_EQ(RunDriver({"--input", dir, "--log", "/nonexistent_dir/x.lcmlog"}).exit_code, kExitOutputError);
  fs::create_directories(dir + "/corrupt");
  WriteTextFile(dir + "/corrupt/0.png", "nope");
  WriteTextFile(dir + "/corrupt/1.png", "nope");
  EXPECT_EQ(RunDriver({"--input", dir + "/corrupt", "--log", dir + "/c.lcmlog"}).exit_code, kExitBadData);
  // One good image among corrupt ones: published, the rest counted and reported.
  cv::imwrite(dir + "/corrupt/2.png", MakeTestImage(8, 8, 1, 2));
  const auto r = RunDriver({"--input", dir + "/corrupt", "--log", dir + "/d.lcmlog"});
  EXPECT_EQ(r.exit_code, kExitOk);
  EXPECT_NE(r.err.find("2 bad frames skipped"), std::string::npos) << r.err;
  EXPECT_EQ(ReadLog(dir + "/d.lcmlog").images.size(), 1u);
}

// The simulator's own fixtures (tools/sim builds them into <build>/fixtures/sim/), when
// present: camera_driver on the folder must reproduce the simulator's sequence.lcmlog.
TEST(CameraDriverLog, SimulatorFixturesMatchTheSimulatorsOwnLog) {
  const std::string fixtures = fs::path(BinPath("camera_driver")).parent_path().parent_path().string() +
                               "/fixtures/sim";
  int checked = 0;
  for (const char* scenario : {"crossing", "robot_odometry", "multi"}) {
    const std::string dir = fixtures + "/" + scenario;
    if (!fs::exists(dir + "/timestamps.txt") || !fs::exists(dir + "/sequence.lcmlog")) continue;
    const std::string log = MakeTempDir("it_simfix") + "/mine.lcmlog";
    const auto r = RunDriver({"--source", "sequence", "--input", dir, "--log", log});
    ASSERT_EQ(r.exit_code, kExitOk) << r.err;
    const DecodedLog mine = ReadLog(log);
    std::vector<LcmLogEvent> events;
    ASSERT_TRUE(ReadLcmLog(dir + "/sequence.lcmlog", &events).ok());
    std::vector<mbslam::image_t> theirs;
    std::vector<mbslam::ground_truth_t> their_truth;
    for (const LcmLogEvent& e : events) {
      if (e.channel == "CAMERA_IMAGE") {
        mbslam::image_t m{};
        ASSERT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
        theirs.push_back(m);
      } else if (e.channel == "GROUND_TRUTH") {
        mbslam::ground_truth_t m{};
        ASSERT_TRUE(DecodeLcmMessage(e.data.data(), e.data.size(), &m).ok());
        their_truth.push_back(m);
      }
    }
    ASSERT_EQ(mine.images.size(), theirs.size()) << scenario;
    ASSERT_EQ(mine.truth.size(), their_truth.size()) << scenario;
    for (size_t i = 0; i < theirs.size(); ++i) {
      EXPECT_EQ(mine.images[i].utime, theirs[i].utime);
      EXPECT_EQ(mine.images[i].seq, theirs[i].seq);
      if (theirs[i].encoding == mine.images[i].encoding) {
        EXPECT_EQ(mine.images[i].data, theirs[i].data);
      }
      EXPECT_TRUE(Identical(Decode(mine.images[i]), Decode(theirs[i]))) << scenario << " " << i;
      EXPECT_EQ(mine.truth[i].source, their_truth[i].source);
      for (int k = 0; k < 3; ++k) EXPECT_NEAR(mine.truth[i].cam_position[k], their_truth[i].cam_position[k], 1e-6);
      ASSERT_EQ(mine.truth[i].num_bodies, their_truth[i].num_bodies) << scenario << " " << i;
      for (size_t b = 0; b < mine.truth[i].bodies.size(); ++b) {
        EXPECT_EQ(mine.truth[i].bodies[b].id, their_truth[i].bodies[b].id);
        EXPECT_EQ(mine.truth[i].bodies[b].visible, their_truth[i].bodies[b].visible) << scenario << " " << i;
        for (int k = 0; k < 3; ++k) {
          EXPECT_NEAR(mine.truth[i].bodies[b].position[k], their_truth[i].bodies[b].position[k], 1e-6);
        }
      }
    }
    ++checked;
  }
  if (checked == 0) GTEST_SKIP() << "no simulator fixtures in " << fixtures;
}

TEST(CameraDriverLog, SigtermDuringPacedPlaybackExitsCleanly) {
  const std::string dir = MakeTempDir("it_sigterm");
  for (int i = 0; i < 20; ++i) cv::imwrite(dir + "/" + std::to_string(i) + ".png", MakeTestImage(8, 8, 1, i));
  // 2 Hz at recorded speed: 10 s of playback, on an in-process bus (no network).
  testing_util::ChildProcess driver({BinPath("camera_driver"), "--quiet", "--no-progress", "--input", dir,
                                     "--rate", "2", "--speed", "1", "--lcm-url", "memq://"});
  // Long enough for the driver to start and install its handler on a loaded machine (a
  // signal before that kills it: seen at 0.7 s under load average 10); still part-way
  // through the 10 s of playback.
  usleep(3000000);
  const int64_t start = MonotonicUtime();
  driver.Signal(SIGTERM);
  const auto r = driver.Wait(5.0);
  EXPECT_EQ(r.exit_code, kExitOk) << r.err;
  EXPECT_LT(MonotonicUtime() - start, 1000000);
  // Stopped part-way: some of the 20 frames, not all (timing decides how many).
  EXPECT_NE(r.err.find("published "), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("published 20 frames"), std::string::npos) << r.err;
}

std::string SharedData(const std::string& sub) {
  for (const char* base : {"../shared/data/", "/work/shared/data/"}) {
    if (fs::exists(std::string(base) + sub)) return std::string(base) + sub;
  }
  return "";
}

TEST(CameraDriverLog, RealTumSubsetAndVideo) {
  const std::string tum = SharedData("tum_fr3_cabinet_subset");
  const std::string video = SharedData("opencv_vtest/vtest.avi");
  if (tum.empty() || video.empty()) GTEST_SKIP() << "../shared/data not present";
  const std::string dir = MakeTempDir("it_real");
  auto r = RunDriver({"--source", "tum", "--input", tum, "--calibration", "config/camera/tum_fr3.yaml",
                      "--encoding", "source", "--log", dir + "/tum.lcmlog"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  DecodedLog decoded = ReadLog(dir + "/tum.lcmlog");
  ASSERT_EQ(decoded.images.size(), 58u);
  ASSERT_EQ(decoded.truth.size(), 58u);
  EXPECT_EQ(decoded.images[0].encoding, mbslam::image_t::ENCODING_JPEG);
  EXPECT_EQ(decoded.images[0].utime, 1341841278842700);
  EXPECT_EQ(decoded.calibrations[0].fx, 535.4);
  r = RunDriver({"--source", "video", "--input", video, "--calibration", "config/camera/vtest_768x576.yaml",
                 "--end-frame", "20", "--color", "gray", "--log", dir + "/vt.lcmlog"});
  ASSERT_EQ(r.exit_code, kExitOk) << r.err;
  decoded = ReadLog(dir + "/vt.lcmlog");
  ASSERT_EQ(decoded.images.size(), 20u);
  EXPECT_EQ(decoded.images[19].utime, 1900000);  // 10 fps
  EXPECT_EQ(decoded.images[0].encoding, mbslam::image_t::ENCODING_GRAY8);
}

}  // namespace
}  // namespace mbslam
