// mbslam-eval end to end: files in, summary and a final JSON line out.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "common/lcm/lcm_log.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/objects_t.hpp"
#include "tools/eval/json.h"
#include "tools/eval/trajectory.h"
#include "test/tools/run_command.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

std::string Bin() { return testing_util::ToolPath("mbslam-eval"); }

// Runs a command; returns its exit status and the JSON object on its last stdout line.
int RunEval(const std::string& args, Json* json) {
  std::string out;
  const int status = testing_util::RunCommand(Bin() + " " + args + " 2>/dev/null", &out);
  if (json && !Json::Parse(testing_util::LastLine(out), json)) {
    *json = Json();
  }
  return status;
}

class EvalCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(Bin())) {
      GTEST_SKIP() << Bin() << " not built";
    }
    dir_ = fs::temp_directory_path() / ("mbslam_eval_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) {
      fs::remove_all(dir_);
    }
  }
  std::string Path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(EvalCli, PerturbThenAteRecoversTheKnownAnswer) {
  Trajectory gt;
  for (int i = 0; i < 200; ++i) {
    const double s = 0.04 * i;
    gt.push_back(
        {1600000000000000 + i * 33333,
         Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(s, Eigen::Vector3d::UnitZ())),
                 Eigen::Vector3d(3 * std::cos(s), 2 * std::sin(s), 0.3 * std::sin(2 * s)))});
  }
  ASSERT_TRUE(WriteTumTrajectory(Path("gt.tum"), gt).ok());
  Json perturb;
  ASSERT_EQ(
      RunEval("perturb --in " + Path("gt.tum") + " --out " + Path("est.tum") +
                  " --scale 0.25 --rot-deg 40 --axis 1,2,3 --trans 1,-2,0.5 --noise 0.02 --seed 3",
              &perturb),
      0);
  const double expected = perturb.Find("expected_ate_sim3_m")->AsDouble();
  EXPECT_GT(expected, 0.02);
  Json ate;
  ASSERT_EQ(RunEval("ate --est " + Path("est.tum") + " --gt " + Path("gt.tum") + " --plot " +
                        Path("plot.png") + " --json " + Path("ate.json"),
                    &ate),
            0);
  // TUM files carry 9 decimals: the answer is exact to ~1e-8 m.
  EXPECT_NEAR(ate.Find("ate_rmse_m")->AsDouble(), expected, 1e-7);
  EXPECT_NEAR(ate.Find("scale")->AsDouble(), 0.25, 1e-9);  // --scale is that of gt_from_est
  EXPECT_EQ(ate.Find("num_pairs")->AsDouble(), 200.0);
  EXPECT_DOUBLE_EQ(ate.Find("fraction_tracked")->AsDouble(), 1.0);
  EXPECT_TRUE(fs::exists(Path("plot.png")));
  EXPECT_TRUE(fs::exists(Path("ate.json")));
  // SE(3) alignment cannot undo the scale.
  Json se3;
  ASSERT_EQ(
      RunEval("ate --est " + Path("est.tum") + " --gt " + Path("gt.tum") + " --align se3", &se3),
      0);
  EXPECT_GT(se3.Find("ate_rmse_m")->AsDouble(), 10 * expected);
  // Bad input fails with a message, not a crash.
  EXPECT_NE(RunEval("ate --est " + Path("missing.tum") + " --gt " + Path("gt.tum"), nullptr), 0);
  EXPECT_NE(
      RunEval("ate --est " + Path("est.tum") + " --gt " + Path("gt.tum") + " --bogus 1", nullptr),
      0);
  EXPECT_NE(RunEval("no-such-command", nullptr), 0);
  // A malformed number fails before any output is written (not with its default).
  EXPECT_EQ(RunEval("perturb --in " + Path("gt.tum") + " --out " + Path("bad.tum") + " --scale 0.3x", nullptr), 1);
  EXPECT_FALSE(fs::exists(Path("bad.tum")));
  EXPECT_EQ(RunEval("ate --est " + Path("est.tum") + " --gt " + Path("gt.tum") + " --max-dt-us 1.5x --plot " +
                        Path("bad.png"),
                    nullptr),
            1);
  EXPECT_FALSE(fs::exists(Path("bad.png")));
}

// --align-est: a second run in the first run's map is scored with the first run's
// alignment as it is; a second run in a map of its own is not rescued by it.
TEST_F(EvalCli, AlignEstScoresARunInAnotherRunsFrame) {
  Trajectory gt;
  for (int i = 0; i < 120; ++i) {
    const double s = 0.05 * i;
    gt.push_back({1600000000000000 + i * 33333,
                  Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(s, Eigen::Vector3d::UnitZ())),
                          Eigen::Vector3d(3 * std::cos(s), 2 * std::sin(s), 0.2 * s))});
  }
  ASSERT_TRUE(WriteTumTrajectory(Path("gt.tum"), gt).ok());
  Json perturb;
  ASSERT_EQ(RunEval("perturb --in " + Path("gt.tum") + " --out " + Path("first.tum") +
                        " --scale 0.5 --rot-deg 30 --axis 0,1,1 --trans 2,0,-1 --noise 0 --seed 1",
                    &perturb),
            0);
  Trajectory first;
  ASSERT_TRUE(ReadTumTrajectory(Path("first.tum"), &first).ok());
  // The second run: the last 60 images, in the first run's map; and the same images in a
  // map of its own (moved 1 unit and turned 10 deg).
  const Trajectory second(first.begin() + 60, first.end());
  Trajectory own = second;
  const Rigid3d other_from_map(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.17, Eigen::Vector3d::UnitX())),
      Eigen::Vector3d(1, 0, 0));
  for (TimedPose& p : own) p.pose = other_from_map * p.pose;
  ASSERT_TRUE(WriteTumTrajectory(Path("second.tum"), second).ok());
  ASSERT_TRUE(WriteTumTrajectory(Path("own.tum"), own).ok());
  const std::string align = " --gt " + Path("gt.tum") + " --align-est " + Path("first.tum") +
                            " --align-gt " + Path("gt.tum");
  Json in_map, elsewhere, own_sim3;
  ASSERT_EQ(RunEval("ate --est " + Path("second.tum") + align, &in_map), 0);
  EXPECT_LT(in_map.Find("ate_rmse_m")->AsDouble(), 1e-6);
  EXPECT_NEAR(in_map.Find("scale")->AsDouble(), 0.5, 1e-6);  // the first run's (gt_from_est)
  EXPECT_EQ(in_map.Find("num_pairs")->AsDouble(), 60.0);
  ASSERT_EQ(RunEval("ate --est " + Path("own.tum") + align, &elsewhere), 0);
  EXPECT_GT(elsewhere.Find("ate_rmse_m")->AsDouble(), 0.3);  // 1 unit is 0.5 m there
  ASSERT_EQ(RunEval("ate --est " + Path("own.tum") + " --gt " + Path("gt.tum"), &own_sim3), 0);
  EXPECT_LT(own_sim3.Find("ate_rmse_m")->AsDouble(), 1e-6);
  // The other run's truth is required, and must be readable.
  EXPECT_NE(RunEval("ate --est " + Path("second.tum") + " --gt " + Path("gt.tum") +
                        " --align-est " + Path("first.tum"),
                    nullptr),
            0);
  EXPECT_NE(RunEval("ate --est " + Path("second.tum") + " --gt " + Path("gt.tum") +
                        " --align-est " + Path("first.tum") + " --align-gt " + Path("missing.tum"),
                    nullptr),
            0);
}

TEST_F(EvalCli, PerturbLabelsThenSegRecoversTheKnownAnswer) {
  {
    FILE* f = std::fopen(Path("truth.txt").c_str(), "w");
    ASSERT_NE(f, nullptr);
    for (int i = 0; i < 300; ++i) {
      std::fprintf(f, "%d ", i < 150 ? 1 : (i < 250 ? 2 : 3));
    }
    std::fclose(f);
  }
  Json p;
  ASSERT_EQ(RunEval("perturb-labels --truth " + Path("truth.txt") + " --out " + Path("pred.txt") +
                        " --wrong 9 --split 4",
                    &p),
            0);
  EXPECT_EQ(p.Find("expected_errors")->AsDouble(), 13.0);
  Json seg;
  ASSERT_EQ(RunEval("seg --pred " + Path("pred.txt") + " --truth " + Path("truth.txt"), &seg), 0);
  EXPECT_DOUBLE_EQ(seg.Find("rate")->AsDouble(), 13.0 / 300.0);
  EXPECT_EQ(seg.Find("pred_groups")->AsDouble(), 4.0);
}

// A run log with poses (half scale), one object following a true body and its 0.2 s
// predictions, plus the ground truth, all in one file.
TEST_F(EvalCli, ObjectsFromLogs) {
  const std::string path = Path("run.lcmlog");
  {
    Status st;
    auto log = LcmLogWriter::Open(path, &st);
    ASSERT_TRUE(log) << st.message();
    auto set_pose = [](const Rigid3d& p, double position[3], double orientation[4]) {
      for (int i = 0; i < 3; ++i) position[i] = p.translation[i];
      orientation[0] = p.rotation.w();
      orientation[1] = p.rotation.x();
      orientation[2] = p.rotation.y();
      orientation[3] = p.rotation.z();
    };
    for (int i = 0; i < 30; ++i) {
      const int64_t t = 1000000 + i * 33333;
      const Rigid3d cam(Eigen::Quaterniond(Eigen::AngleAxisd(0.02 * i, Eigen::Vector3d::UnitY())),
                        Eigen::Vector3d(0.1 * i, 0.01 * i * i, 0.05 * i));
      const Eigen::Vector3d body(6.0, -2.0 + 0.05 * i, 0.9);
      mbslam::ground_truth_t gt{};
      gt.utime = t;
      gt.source = "test";
      gt.has_camera = 1;
      set_pose(cam, gt.cam_position, gt.cam_orientation);
      mbslam::body_state_t b{};
      b.id = 3;
      b.name = "person";
      set_pose(Rigid3d(Eigen::Quaterniond::Identity(), body), b.position, b.orientation);
      gt.bodies.push_back(b);
      gt.num_bodies = 1;
      ASSERT_TRUE(log->Write("GROUND_TRUTH", t, gt).ok());
      mbslam::camera_pose_t pose{};
      pose.utime = t;
      set_pose(Rigid3d(cam.rotation, 0.5 * cam.translation), pose.position, pose.orientation);
      pose.tracking_state = mbslam::camera_pose_t::TRACKING_OK;
      ASSERT_TRUE(log->Write("PERCEPTION_CAMERA_POSE", t, pose).ok());
      mbslam::objects_t objs{};
      objs.utime = t;
      mbslam::object_t o{};
      o.id = 8;
      for (int k = 0; k < 3; ++k) o.position[k] = 0.5 * body[k];
      o.orientation[0] = 1.0;
      mbslam::predicted_volume_t v{};
      v.horizon_us = 200000;
      v.utime = t + v.horizon_us;
      const Eigen::Vector3d future = 0.5 * (body + Eigen::Vector3d(0.0, 0.05 * 6, 0.0));
      for (int k = 0; k < 3; ++k)
        v.center[k] = future[k] + (i % 3 == 0 ? 1.0 : 0.0);  // a third miss
      v.orientation[0] = 1.0;
      v.half_extent[0] = v.half_extent[1] = v.half_extent[2] = 0.25;
      o.volumes.push_back(v);
      o.num_volumes = 1;
      objs.objects.push_back(o);
      objs.num_objects = 1;
      ASSERT_TRUE(log->Write("PERCEPTION_OBJECTS", t, objs).ok());
    }
  }
  Json j;
  ASSERT_EQ(RunEval("objects --est-log " + path + " --gt-log " + path + " --horizon-us 200000", &j),
            0);
  EXPECT_EQ(j.Find("matched")->AsDouble(), 1.0);
  EXPECT_LT(j.Find("camera_ate_rmse_m")->AsDouble(), 1e-9);
  const Json& obj = (*j.Find("objects"))[0];
  EXPECT_LT(obj.Find("position_rmse_m")->AsDouble(), 1e-9);
  EXPECT_NEAR(obj.Find("best_scale")->AsDouble(), 1.0, 1e-9);
  // Predictions 0.2 s ahead land within the truth for frames 0-22 (frame 23's is 2 µs
  // past the last truth); every third (0, 3, ..., 21: 8 of them) is off by 1 m.
  EXPECT_EQ(j.Find("volumes_checked")->AsDouble(), 23.0);
  EXPECT_NEAR(j.Find("volume_hit_rate")->AsDouble(), 15.0 / 23.0, 1e-12);

  // --dump: one row per matched sample, truth and estimate in the true camera's frame.
  const std::string dump = Path("objects.csv");
  ASSERT_EQ(RunEval("objects --est-log " + path + " --gt-log " + path + " --dump " + dump, &j), 0);
  std::ifstream in(dump);
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line.rfind("est_id,body,t_s,true_x,true_y,true_z,est_x,est_y,est_z,", 0), 0u) << line;
  int rows = 0;
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) v.push_back(cell == "person" ? 0.0 : std::stod(cell));
    ASSERT_EQ(v.size(), 12u) << line;
    EXPECT_EQ(v[0], 8.0);
    for (int k = 3; k < 6; ++k) EXPECT_NEAR(v[k], v[k + 3], 1e-3) << line;  // estimate = truth
    EXPECT_NEAR(v[9], 0.9, 1e-3);                                           // body height
    ++rows;
  }
  EXPECT_EQ(rows, 30);
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
