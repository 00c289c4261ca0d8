#include "services/perception/perception_options.h"

#include <gtest/gtest.h>

#include "common/config/options_yaml.h"
#include "common/util/atomic_file.h"

namespace mbslam {
namespace {

// config/perception.yaml must list every option with its default value: loading it
// gives the defaults, and it prints back to the same text.
TEST(PerceptionOptions, ConfigFileListsEveryOptionWithItsDefault) {
  const std::string path = "config/perception.yaml";
  std::string text;
  ASSERT_TRUE(ReadFileToString(path, &text).ok()) << "run from the repository root";
  PerceptionOptions loaded;
  const Status s = LoadOptionsFromFile(path, &loaded);
  ASSERT_TRUE(s.ok()) << s.message();
  const std::string defaults = OptionsToYaml(PerceptionOptions());
  EXPECT_EQ(OptionsToYaml(loaded), defaults);
  // Every line of the defaults appears verbatim in the file (comments included).
  size_t pos = 0;
  while (pos < defaults.size()) {
    const size_t end = defaults.find('\n', pos);
    const std::string line = defaults.substr(pos, end - pos);
    EXPECT_NE(text.find(line), std::string::npos) << "config/perception.yaml lacks: " << line;
    pos = end + 1;
  }
}

TEST(PerceptionOptions, DefaultsPassCheck) { EXPECT_TRUE(PerceptionOptions().Check()); }

// A lockstep replay gives the same result on a loaded machine: its bundle adjustments run
// inline and are bounded by iterations, not wall time. Live, they are time-limited.
TEST(PerceptionOptions, LockstepBundleAdjustmentIgnoresWallTime) {
  PerceptionOptions live;
  EXPECT_TRUE(live.core().slam.ba.time_limited);
  EXPECT_TRUE(live.core().slam.background_ba);
  PerceptionOptions replay;
  replay.pipeline.mode = "lockstep";
  EXPECT_FALSE(replay.core().slam.ba.time_limited);
  EXPECT_FALSE(replay.core().slam.background_ba);
  EXPECT_TRUE(replay.core().wait_for_person_checks);
}

}  // namespace
}  // namespace mbslam
