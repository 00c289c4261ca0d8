// mbslam-sim's command line: a malformed or out-of-range number is refused (status 2,
// the option named) before anything is written, a value the options refuse (frames 0) too;
// a valid override reaches the options.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "test/tools/run_command.h"

namespace {

namespace fs = std::filesystem;

// Runs the executable; its exit status, its stdout and stderr in `out`.
int RunSim(const std::string& args, std::string* out) {
  return mbslam::testing_util::RunCommand(mbslam::testing_util::ToolPath("mbslam-sim") + " " + args + " 2>&1", out);
}

TEST(SimCli, MalformedNumbersAreRefusedBeforeAnyWork) {
  const fs::path dir = fs::temp_directory_path() / ("sim_cli_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const std::string base = "--scenario static --size 64x48 --out " + dir.string();
  std::string out;
  EXPECT_EQ(RunSim(base + " --frames 3x", &out), 2);
  EXPECT_NE(out.find("--frames"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --fps abc", &out), 2);
  EXPECT_NE(out.find("--fps"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --noise nan", &out), 2);
  EXPECT_NE(out.find("--noise"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --blur 2.5", &out), 2);
  EXPECT_NE(out.find("--blur"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --seed -1", &out), 2);
  EXPECT_NE(out.find("--seed"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --frames 99999999999", &out), 2);
  EXPECT_NE(out.find("--frames"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --check-frames x", &out), 2);
  EXPECT_EQ(RunSim(base + " --size 64x48junk", &out), 2);
  EXPECT_NE(out.find("--size"), std::string::npos) << out;
  // Well-formed but refused by the options (a value <= 0 used to be skipped as 'not given').
  EXPECT_EQ(RunSim(base + " --frames 0", &out), 2);
  EXPECT_NE(out.find("num_frames"), std::string::npos) << out;
  EXPECT_EQ(RunSim(base + " --fps -5", &out), 2);
  EXPECT_NE(out.find("fps"), std::string::npos) << out;
  EXPECT_FALSE(fs::exists(dir)) << "nothing written for a refused command line";
}

TEST(SimCli, OverridesReachTheOptions) {
  std::string out;
  ASSERT_EQ(RunSim("--scenario crossing --frames 7 --fps 12.5 --seed 42 --noise 1.5 --blur 3 --print-config", &out), 0)
      << out;
  EXPECT_NE(out.find("num_frames: 7 "), std::string::npos) << out;
  EXPECT_NE(out.find("fps: 12.5 "), std::string::npos) << out;
  EXPECT_NE(out.find("seed: 42 "), std::string::npos) << out;
  EXPECT_NE(out.find("noise_sigma: 1.5 "), std::string::npos) << out;
  EXPECT_NE(out.find("motion_blur_samples: 3 "), std::string::npos) << out;
}

}  // namespace
