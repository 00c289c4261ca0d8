#include "common/util/logging.h"

#include <gtest/gtest.h>

namespace mbslam {
namespace {

TEST(Logging, ParseLevels) {
  LogLevel level;
  EXPECT_TRUE(ParseLogLevel("warning", &level));
  EXPECT_EQ(level, LogLevel::kWarning);
  EXPECT_TRUE(ParseLogLevel("debug", &level));
  EXPECT_EQ(level, LogLevel::kDebug);
  EXPECT_FALSE(ParseLogLevel("loud", &level));
}

TEST(Logging, DisabledLevelDoesNotEvaluateStream) {
  const LogLevel saved = GetLogLevel();
  SetLogLevel(LogLevel::kError);
  int evaluated = 0;
  auto side_effect = [&] { return ++evaluated; };
  MBSLAM_LOG(INFO) << side_effect();
  EXPECT_EQ(evaluated, 0);
  testing::internal::CaptureStderr();
  MBSLAM_LOG(ERROR) << "value " << side_effect();
  const std::string out = testing::internal::GetCapturedStderr();
  EXPECT_EQ(evaluated, 1);
  EXPECT_NE(out.find("logging_test.cc"), std::string::npos);
  EXPECT_NE(out.find("value 1"), std::string::npos);
  EXPECT_EQ(out[0], 'E');
  SetLogLevel(saved);
}

}  // namespace
}  // namespace mbslam
