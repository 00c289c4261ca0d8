// mbslam-eval end to end: files in, summary and a final JSON line out.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include "tools/eval/json.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

std::string Bin() {
  const char* dir = std::getenv("MBSLAM_BIN_DIR");
  return std::string(dir ? dir : "build/bin") + "/mbslam-eval";
}

// Runs a command; returns its exit status and the JSON object on its last stdout line.
int RunEval(const std::string& args, Json* json) {
  const std::string cmd = Bin() + " " + args + " 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) {
    return -1;
  }
  std::string out;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof(buf), pipe)) {
    out.append(buf, n);
  }
  const int status = pclose(pipe);
  while (!out.empty() && out.back() == '\n') {
    out.pop_back();
  }
  const size_t nl = out.rfind('\n');
  const std::string last = nl == std::string::npos ? out : out.substr(nl + 1);
  if (json && !Json::Parse(last, json)) {
    *json = Json();
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
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

}  // namespace
}  // namespace eval
}  // namespace mbslam
