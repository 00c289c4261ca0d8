#include "common/util/command_line.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mbslam {
namespace {

CommandLineArgs Parse(const std::vector<const char*>& words, int first = 1) {
  return CommandLineArgs(static_cast<int>(words.size()), words.data(), first);
}

TEST(ParseNumberTest, WholeFiniteNumbersOnly) {
  double d = 0;
  int64_t i = 0;
  EXPECT_TRUE(ParseDouble("2.5", "x", &d).ok());
  EXPECT_EQ(d, 2.5);
  EXPECT_TRUE(ParseDouble("-1e-3", "x", &d).ok());
  EXPECT_EQ(d, -1e-3);
  EXPECT_FALSE(ParseDouble("2.5x", "x", &d).ok());
  EXPECT_FALSE(ParseDouble("", "x", &d).ok());
  EXPECT_FALSE(ParseDouble("nan", "x", &d).ok());
  EXPECT_FALSE(ParseDouble("inf", "x", &d).ok());
  EXPECT_FALSE(ParseDouble("1e999", "x", &d).ok());
  EXPECT_EQ(ParseDouble("2.5x", "--scale", &d).message(), "--scale: '2.5x' is not a number");
  EXPECT_TRUE(ParseInt64("-42", "n", &i).ok());
  EXPECT_EQ(i, -42);
  EXPECT_FALSE(ParseInt64("4.2", "n", &i).ok());
  EXPECT_FALSE(ParseInt64("99999999999999999999", "n", &i).ok());
}

TEST(ParseNumberTest, ImageSizesWhole) {
  int w = 0, h = 0;
  ASSERT_TRUE(ParseImageSize("640x480", "--size", &w, &h).ok());
  EXPECT_EQ(w, 640);
  EXPECT_EQ(h, 480);
  for (const char* bad : {"", "640", "640x", "x480", "640x480junk", "64x48x2", "0x480", "640x0", "-640x480",
                          "640x-480", "+640x480", " 640x480", "640x 480", "70000x480", "640X480", "6.5x4"}) {
    const Status st = ParseImageSize(bad, "--size", &w, &h);
    EXPECT_FALSE(st.ok()) << bad;
    EXPECT_NE(st.message().find("--size"), std::string::npos) << bad;
  }
  EXPECT_EQ(w, 640) << "a refused size leaves the values";
}

TEST(CommandLineArgsTest, ValuesFlagsAndNegativeNumbers) {
  const CommandLineArgs args =
      Parse({"tool", "--in", "a.txt", "--verbose", "--scale", "-2.5", "--seed", "7", "--json"});
  EXPECT_EQ(args.Get("in"), "a.txt");
  EXPECT_TRUE(args.Has("verbose"));
  EXPECT_EQ(args.Get("verbose", "x"), "");  // a bare flag has no value
  EXPECT_EQ(args.Get("missing", "x"), "x");
  EXPECT_DOUBLE_EQ(args.GetDouble("scale", 1.0), -2.5);
  EXPECT_EQ(args.GetInt("seed", 1), 7);
  EXPECT_TRUE(args.Has("json"));
  EXPECT_EQ(args.GetDouble("missing", 0.25), 0.25);
  EXPECT_EQ(args.GetInt("missing", -3), -3);
  EXPECT_EQ(args.Problems(), "");
}

TEST(CommandLineArgsTest, RepeatedOptionsKeepEveryValue) {
  const CommandLineArgs args = Parse({"tool", "--exclude", "a", "--exclude", "b", "--n", "1", "--n", "2"});
  EXPECT_EQ(args.GetAll("exclude"), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(args.Get("exclude"), "b");  // the last
  EXPECT_EQ(args.GetInt("n", 0), 2);
  EXPECT_TRUE(args.GetAll("missing").empty());
  EXPECT_EQ(args.Problems(), "");
}

TEST(CommandLineArgsTest, ASubcommandIsSkipped) {
  const CommandLineArgs args = Parse({"mbslam-eval", "ate", "--est", "e.tum"}, 2);
  EXPECT_EQ(args.Get("est"), "e.tum");
  EXPECT_EQ(args.Problems(), "");
}

TEST(CommandLineArgsTest, UnknownOptionsAreProblems) {
  const CommandLineArgs args = Parse({"tool", "--in", "a", "--typo", "3"});
  EXPECT_EQ(args.Get("in"), "a");
  EXPECT_EQ(args.Problems(), "unknown option --typo");
}

TEST(CommandLineArgsTest, StrayArgumentsAreProblems) {
  EXPECT_EQ(Parse({"tool", "a.txt"}).Problems(), "unexpected argument 'a.txt'");
  EXPECT_EQ(Parse({"tool", "--"}).Problems(), "unexpected argument '--'");
}

TEST(CommandLineArgsTest, MalformedNumbersAreProblemsAndGiveTheFallback) {
  const CommandLineArgs args =
      Parse({"tool", "--a", "1.5x", "--b", "12", "--c", "1e999", "--d", "3.0", "--e", "--f", "nan"});
  EXPECT_EQ(args.GetDouble("a", 9.0), 9.0);
  EXPECT_EQ(args.GetInt("b", 0), 12);
  EXPECT_EQ(args.GetDouble("c", 9.0), 9.0);  // out of range
  EXPECT_EQ(args.GetInt("d", 4), 4);         // not a whole number
  EXPECT_EQ(args.GetDouble("e", 2.0), 2.0);  // a bare flag is no number
  EXPECT_EQ(args.GetDouble("f", 2.0), 2.0);  // not finite
  EXPECT_EQ(args.Problems(), "--a: '1.5x' is not a number");  // the first one
  EXPECT_EQ(args.ParseProblems(), args.Problems());
}

TEST(CommandLineArgsTest, ParseProblemsLeaveUnknownOptionsForLater) {
  const CommandLineArgs args = Parse({"tool", "--n", "3", "--later", "x"});
  EXPECT_EQ(args.GetInt("n", 0), 3);
  EXPECT_EQ(args.ParseProblems(), "");  // --later may still be read
  EXPECT_EQ(args.Get("later"), "x");
  EXPECT_EQ(args.Problems(), "");
  EXPECT_EQ(Parse({"tool", "stray"}).ParseProblems(), "unexpected argument 'stray'");
}

}  // namespace
}  // namespace mbslam
