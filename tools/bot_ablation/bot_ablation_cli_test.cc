// mbslam-bot-ablation's command line: a malformed number, an unknown option, a value
// given to the flag or a value out of range is refused (status 2, the option named)
// before any work; a small valid run writes its figures.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "test/tools/run_command.h"

namespace {

namespace fs = std::filesystem;

// Runs the executable; its exit status, its stdout and stderr in `out`.
int RunTool(const std::string& args, std::string* out) {
  return mbslam::testing_util::RunCommand(mbslam::testing_util::ToolPath("mbslam-bot-ablation") + " " + args + " 2>&1",
                                          out);
}

class BotAblationCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("bot_ablation_cli_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(BotAblationCli, BadArgumentsAreRefusedBeforeAnyWork) {
  const std::string out_dir = "--out " + dir_.string();
  std::string out;
  EXPECT_EQ(RunTool(out_dir + " --seeds 2x", &out), 2);
  EXPECT_NE(out.find("--seeds"), std::string::npos) << out;
  EXPECT_EQ(RunTool(out_dir + " --wiggle abc", &out), 2);
  EXPECT_NE(out.find("--wiggle"), std::string::npos) << out;
  EXPECT_EQ(RunTool(out_dir + " --duration nan", &out), 2);
  EXPECT_NE(out.find("--duration"), std::string::npos) << out;
  EXPECT_EQ(RunTool(out_dir + " --bogus 1", &out), 2);
  EXPECT_NE(out.find("--bogus"), std::string::npos) << out;
  EXPECT_EQ(RunTool(out_dir + " --noise-in-units 1", &out), 2);
  EXPECT_NE(out.find("--noise-in-units"), std::string::npos) << out;
  EXPECT_EQ(RunTool(out_dir + " --seeds 0", &out), 2);
  EXPECT_EQ(RunTool(out_dir + " --particles 99999999999", &out), 2);
  EXPECT_FALSE(fs::exists(dir_)) << "nothing written for a refused command line";
}

TEST_F(BotAblationCli, ASmallRunWritesItsFigures) {
  std::string out;
  ASSERT_EQ(RunTool("--out " + dir_.string() + " --seeds 1 --particles 100 --camera car --noise-in-units", &out), 0)
      << out;
  EXPECT_NE(out.find("\"seeds\": 1"), std::string::npos) << out;
  EXPECT_NE(out.find("\"particles\": 100"), std::string::npos) << out;
  EXPECT_TRUE(fs::exists(dir_ / "bot_ablation.png"));
}

}  // namespace
