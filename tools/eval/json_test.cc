#include "tools/eval/json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace mbslam {
namespace eval {
namespace {

TEST(Json, DumpsInInsertionOrder) {
  Json j = Json::Object();
  j.Set("b", 1).Set("a", 2.5).Set("s", "x\"y\n").Set("t", true).Set("n", Json());
  j.Set("arr", Json(std::vector<double>{1.0, 0.5}));
  j.Set("b", int64_t{7});  // replaces, keeps position
  EXPECT_EQ(j.Dump(),
            R"({"b": 7, "a": 2.5, "s": "x\"y\n", "t": true, "n": null, "arr": [1, 0.5]})");
}

TEST(Json, NonFiniteIsNull) {
  Json j = Json::Object();
  j.Set("nan", std::numeric_limits<double>::quiet_NaN())
      .Set("inf", std::numeric_limits<double>::infinity());
  EXPECT_EQ(j.Dump(), R"({"nan": null, "inf": null})");
}

TEST(Json, ParseRoundTrip) {
  Json j = Json::Object();
  j.Set("x", 0.125)
      .Set("k", int64_t{-3})
      .Set("name", "sim:multi")
      .Set("nested", Json::Object().Set("y", 1));
  j.Set("list", Json::Array().Push(1).Push("two").Push(Json::Array()));
  Json back;
  std::string error;
  ASSERT_TRUE(Json::Parse(j.Dump(), &back, &error)) << error;
  EXPECT_EQ(back.Dump(), j.Dump());
  EXPECT_DOUBLE_EQ(back.Find("x")->AsDouble(), 0.125);
  EXPECT_EQ(back.Find("name")->AsString(), "sim:multi");
  EXPECT_EQ(back.Find("missing"), nullptr);
  EXPECT_FALSE(Json::Parse("{\"a\": }", &back));
  EXPECT_FALSE(Json::Parse("[1, 2", &back));
  EXPECT_FALSE(Json::Parse("{} trailing", &back));
}

}  // namespace
}  // namespace eval
}  // namespace mbslam
