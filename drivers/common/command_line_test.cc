#include "drivers/common/command_line.h"

#include <gtest/gtest.h>

#include "common/lcm/channels.h"

namespace mbslam {
namespace {

struct TestOptions {
  int count = 1;  // a count
  ChannelOptions channels;
  bool Check() const {
    MBSLAM_CHECK_OPTION_GT(count, 0);
    MBSLAM_CHECK_OPTION_SECTION(channels);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("count", &count, "a count");
    v("channels", &channels, "channel names");
  }
};

Status ParseArgs(std::vector<const char*> args, CommandLine* cl) {
  args.insert(args.begin(), "prog");
  return CommandLine::Parse(static_cast<int>(args.size()), args.data(), {"verbose"},
                            {"input", "set"}, cl);
}

TEST(CommandLine, ParsesFlagsValuesAndPositionals) {
  CommandLine cl;
  ASSERT_TRUE(ParseArgs({"--verbose", "--input", "a.txt", "--set=x=1", "--set", "y=2", "pos"}, &cl).ok());
  EXPECT_TRUE(cl.Has("verbose"));
  EXPECT_EQ(cl.Get("input"), "a.txt");
  EXPECT_EQ(cl.GetAll("set"), (std::vector<std::string>{"x=1", "y=2"}));
  EXPECT_EQ(cl.positional(), std::vector<std::string>{"pos"});
  EXPECT_EQ(cl.Get("missing", "fallback"), "fallback");
}

TEST(CommandLine, RejectsUnknownOptionsAndMissingValues) {
  CommandLine cl;
  EXPECT_FALSE(ParseArgs({"--bogus"}, &cl).ok());
  EXPECT_FALSE(ParseArgs({"--input"}, &cl).ok());
  EXPECT_FALSE(ParseArgs({"--verbose=1"}, &cl).ok());
}

TEST(CommandLine, AssignmentSetsNestedOptionsAndIsChecked) {
  TestOptions options;
  ASSERT_TRUE(ApplyOptionAssignment("channels.camera_image=MY_IMAGES", &options).ok());
  EXPECT_EQ(options.channels.camera_image, "MY_IMAGES");
  EXPECT_EQ(options.channels.odometry, "ODOMETRY");  // untouched
  ASSERT_TRUE(ApplyOptionAssignment("count=7", &options).ok());
  EXPECT_EQ(options.count, 7);
  EXPECT_FALSE(ApplyOptionAssignment("count=-1", &options).ok());  // Check() fails
  EXPECT_EQ(options.count, 7);
  EXPECT_FALSE(ApplyOptionAssignment("channels.nope=X", &options).ok());
  EXPECT_FALSE(ApplyOptionAssignment("count=abc", &options).ok());
  EXPECT_FALSE(ApplyOptionAssignment("noequals", &options).ok());
  EXPECT_FALSE(ApplyOptionAssignment("a..b=1", &options).ok());
}

}  // namespace
}  // namespace mbslam
