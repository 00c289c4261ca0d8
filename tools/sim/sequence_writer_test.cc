#include "tools/sim/sequence_writer.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <map>

#include "common/lcm/lcm_log.h"
#include "common/util/atomic_file.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "tools/eval/datasets.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace sim {
namespace {

namespace fs = std::filesystem;

std::string TempDir(const std::string& name) {
  const fs::path dir =
      fs::temp_directory_path() / ("mbslam_sim_test_" + std::to_string(::getpid()) + "_" + name);
  fs::remove_all(dir);
  return dir.string();
}

template <typename Msg>
Msg Decode(const LcmLogEvent& e) {
  Msg msg{};
  EXPECT_GE(msg.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0) << e.channel;
  return msg;
}

std::unique_ptr<Simulator> MakeSim(const std::string& scenario, int frames) {
  SimOptions o;
  o.scenario = scenario;
  o.num_frames = frames;
  o.camera.width = 160;
  o.camera.height = 120;
  Status status;
  auto sim = Simulator::Create(o, &status);
  EXPECT_TRUE(sim) << status.message();
  return sim;
}

TEST(SequenceWriter, FolderAndLogMatchTheSimulator) {
  auto sim = MakeSim("robot_odometry", 40);
  ASSERT_TRUE(sim);
  const std::string dir = TempDir("robot");
  SequenceWriterOptions options;
  options.calibration_period_s = 0.5;
  SequenceSummary summary;
  int progress_calls = 0;
  ASSERT_TRUE(
      WriteSequence(sim.get(), dir, options, &summary, [&](int) { ++progress_calls; }).ok());
  EXPECT_EQ(summary.frames, 40);
  EXPECT_EQ(progress_calls, 40);

  for (const char* f :
       {"scenario.yaml", "calibration.yaml", "timestamps.txt", "cam_trajectory.tum", "objects.yaml",
        "odometry.tum", "odometry_truth.tum", "extrinsic.yaml", "sequence.lcmlog", "points/0.txt",
        "points/1.txt", "objects/1.tum", "images/000000.png", "images/000039.png",
        "masks/000039.png", "depth/000039.exr"}) {
    EXPECT_TRUE(fs::exists(fs::path(dir) / f)) << f;
  }
  EXPECT_FALSE(fs::exists(fs::path(dir) / "images/000040.png"));

  // Intrinsics round trip.
  CameraIntrinsics K;
  ASSERT_TRUE(LoadCameraIntrinsics(dir + "/calibration.yaml", &K).ok());
  EXPECT_DOUBLE_EQ(K.fx, sim->intrinsics().fx);
  EXPECT_DOUBLE_EQ(K.cy, sim->intrinsics().cy);
  EXPECT_EQ(K.width, 160);

  // Trajectories round trip exactly in time, to 1e-9 in pose.
  eval::Trajectory cam;
  ASSERT_TRUE(eval::ReadTumTrajectory(dir + "/cam_trajectory.tum", &cam).ok());
  ASSERT_EQ(cam.size(), 40u);
  for (int k = 0; k < 40; ++k) {
    EXPECT_EQ(cam[static_cast<size_t>(k)].utime, sim->FrameUtime(k));
    EXPECT_LT(TranslationDistance(cam[static_cast<size_t>(k)].pose,
                                  sim->WorldFromCam(sim->FrameUtime(k))),
              1e-8);
  }
  eval::Trajectory obj;
  ASSERT_TRUE(eval::ReadTumTrajectory(dir + "/objects/2.tum", &obj).ok());
  ASSERT_EQ(obj.size(), 40u);
  EXPECT_LT(RotationDistance(obj[17].pose, sim->WorldFromBody(2, sim->FrameUtime(17))), 1e-8);
  eval::Trajectory odo;
  ASSERT_TRUE(eval::ReadTumTrajectory(dir + "/odometry.tum", &odo).ok());
  EXPECT_EQ(odo.size(), sim->odometry().size());

  // Extrinsic.
  const YAML::Node ext = YAML::LoadFile(dir + "/extrinsic.yaml");
  ASSERT_TRUE(ext["translation"] && ext["quaternion"]);
  const Rigid3d base_from_cam = *sim->base_from_cam();
  EXPECT_NEAR(ext["translation"][2].as<double>(), base_from_cam.translation.z(), 1e-9);
  EXPECT_NEAR(ext["quaternion"][0].as<double>(), base_from_cam.rotation.w(), 1e-9);
  const YAML::Node objects = YAML::LoadFile(dir + "/objects.yaml");
  ASSERT_EQ(objects["objects"].size(), sim->MovingBodyIds().size());
  EXPECT_EQ(objects["objects"][0]["name"].as<std::string>(), "person");

  // Images, masks, depth equal the in-memory frame.
  SimFrame f;
  ASSERT_TRUE(sim->RenderFrame(39, &f).ok());
  const cv::Mat img = cv::imread(dir + "/images/000039.png", cv::IMREAD_UNCHANGED);
  const cv::Mat mask = cv::imread(dir + "/masks/000039.png", cv::IMREAD_UNCHANGED);
  const cv::Mat depth = cv::imread(dir + "/depth/000039.exr", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(img.type(), CV_8UC1);
  ASSERT_EQ(mask.type(), CV_16UC1);
  ASSERT_EQ(depth.type(), CV_32FC1);
  EXPECT_EQ(cv::norm(img, f.image_gray, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(mask, f.mask, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(depth, f.depth, cv::NORM_INF), 0.0);

  // The log: time ordered, every message decodes, event time = message time.
  std::vector<LcmLogEvent> events;
  ASSERT_TRUE(ReadLcmLog(dir + "/sequence.lcmlog", &events).ok());
  EXPECT_EQ(static_cast<int64_t>(events.size()), summary.lcm_events);
  std::map<std::string, int> count;
  int64_t last = 0;
  bool calibration_before_first_image = false;
  for (const auto& e : events) {
    EXPECT_GE(e.timestamp, last);
    last = e.timestamp;
    ++count[e.channel];
    if (e.channel == "CAMERA_IMAGE") {
      const auto msg = Decode<mbslam::image_t>(e);
      EXPECT_EQ(msg.utime, e.timestamp);
      EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_GRAY8);
      EXPECT_EQ(msg.size, 160 * 120);
      EXPECT_EQ(msg.row_stride, 160);
      if (msg.seq == 0) {
        calibration_before_first_image = count["CAMERA_CALIBRATION"] == 1;
      }
      if (msg.seq == 39) {
        const cv::Mat m(120, 160, CV_8UC1, const_cast<uint8_t*>(msg.data.data()));
        EXPECT_EQ(cv::norm(m, f.image_gray, cv::NORM_INF), 0.0);
      }
    } else if (e.channel == "GROUND_TRUTH") {
      const auto msg = Decode<mbslam::ground_truth_t>(e);
      EXPECT_EQ(msg.utime, e.timestamp);
      EXPECT_EQ(msg.source, "sim:robot_odometry");
      EXPECT_EQ(msg.has_camera, 1);
      ASSERT_EQ(msg.num_bodies, 3);
      const Rigid3d cam = sim->WorldFromCam(msg.utime);
      EXPECT_NEAR(msg.cam_orientation[0], cam.rotation.w(), 1e-12);
      EXPECT_NEAR(msg.cam_position[1], cam.translation.y(), 1e-12);
      EXPECT_EQ(msg.bodies[1].id, 2);
      EXPECT_NEAR(msg.bodies[1].extent[0], 4.2, 1e-12);
      if (msg.frame_seq == 39) {
        EXPECT_EQ(msg.bodies[0].visible, f.bodies[0].visible ? 1 : 0);
      }
    } else if (e.channel == "CAMERA_CALIBRATION") {
      const auto msg = Decode<mbslam::camera_calibration_t>(e);
      EXPECT_DOUBLE_EQ(msg.fx, sim->intrinsics().fx);
      EXPECT_EQ(msg.num_distortion, 0);
    } else if (e.channel == "ODOMETRY") {
      const auto msg = Decode<mbslam::odometry_t>(e);
      EXPECT_EQ(msg.utime, e.timestamp);
      EXPECT_EQ(msg.frame_id, "odom");
      EXPECT_NEAR(
          msg.orientation[0] * msg.orientation[0] + msg.orientation[3] * msg.orientation[3] +
              msg.orientation[1] * msg.orientation[1] + msg.orientation[2] * msg.orientation[2],
          1.0, 1e-9);
    } else {
      ADD_FAILURE() << "unexpected channel " << e.channel;
    }
  }
  EXPECT_TRUE(calibration_before_first_image);

  // The evaluation toolkit reads the folder back.
  eval::SequenceFolder folder;
  ASSERT_TRUE(eval::ReadSequenceFolder(dir, &folder).ok());
  EXPECT_EQ(folder.utimes.size(), 40u);
  EXPECT_EQ(folder.utimes[7], sim->FrameUtime(7));
  EXPECT_EQ(folder.camera.size(), 40u);
  EXPECT_EQ(folder.images.size(), 40u);
  EXPECT_EQ(folder.masks.size(), 40u);
  EXPECT_EQ(folder.depths.size(), 40u);
  EXPECT_DOUBLE_EQ(folder.intrinsics.fx, sim->intrinsics().fx);
  ASSERT_EQ(folder.bodies.size(), 3u);
  EXPECT_EQ(folder.bodies.at(2).name, "car");
  EXPECT_NEAR(folder.bodies.at(2).extent.x(), 4.2, 1e-9);
  EXPECT_EQ(folder.bodies.at(2).poses.size(), 40u);
  ASSERT_EQ(folder.points.count(0), 1u);
  EXPECT_EQ(folder.points.at(0).size(), sim->SurfacePoints(0).size());
  EXPECT_LT((folder.points.at(1)[5] - sim->SurfacePoints(1)[5]).norm(), 1e-5);
  EXPECT_EQ(count["CAMERA_IMAGE"], 40);
  EXPECT_EQ(count["GROUND_TRUTH"], 40);
  EXPECT_EQ(count["CAMERA_CALIBRATION"], 3);  // t = 0, 0.5 s, 1.0 s... of 1.3 s
  EXPECT_EQ(count["ODOMETRY"], static_cast<int>(sim->odometry().size()));
  fs::remove_all(dir);
}

TEST(SequenceWriter, DeterministicLogAndOptions) {
  auto a = MakeSim("crossing", 8);
  auto b = MakeSim("crossing", 8);
  ASSERT_TRUE(a && b);
  SequenceWriterOptions options;
  options.write_files = false;
  options.lcm_image_encoding = "png";
  options.channels.camera_image = "SIM_IMAGE";
  const std::string da = TempDir("det_a"), db = TempDir("det_b");
  SequenceSummary sa, sb;
  ASSERT_TRUE(WriteSequence(a.get(), da, options, &sa).ok());
  ASSERT_TRUE(WriteSequence(b.get(), db, options, &sb).ok());
  EXPECT_FALSE(fs::exists(fs::path(da) / "images"));
  std::string la, lb;
  ASSERT_TRUE(ReadFileToString(da + "/sequence.lcmlog", &la).ok());
  ASSERT_TRUE(ReadFileToString(db + "/sequence.lcmlog", &lb).ok());
  EXPECT_EQ(la, lb);  // byte-identical
  std::vector<LcmLogEvent> events;
  ASSERT_TRUE(ReadLcmLog(da + "/sequence.lcmlog", &events, "SIM_IMAGE").ok());
  ASSERT_EQ(events.size(), 8u);
  const auto msg = Decode<mbslam::image_t>(events[3]);
  EXPECT_EQ(msg.encoding, mbslam::image_t::ENCODING_PNG);
  EXPECT_EQ(msg.row_stride, 0);
  const cv::Mat decoded = cv::imdecode(msg.data, cv::IMREAD_UNCHANGED);
  EXPECT_EQ(decoded.size(), cv::Size(160, 120));

  options.depth_format = "tiff";
  EXPECT_FALSE(WriteSequence(a.get(), da, options, &sa).ok());
  fs::remove_all(da);
  fs::remove_all(db);
}

}  // namespace
}  // namespace sim
}  // namespace mbslam
