#include "common/util/request_path.h"

#include <gtest/gtest.h>

#include <string>

namespace mbslam {
namespace {

TEST(ResolveRequestPath, RelativeRequestsStayUnderTheBase) {
  std::string r;
  ASSERT_TRUE(ResolveRequestPath("out", "", false, &r).ok());
  EXPECT_EQ(r, "out/");
  ASSERT_TRUE(ResolveRequestPath("out", "run1/snap_", false, &r).ok());
  EXPECT_EQ(r, "out/run1/snap_");
  ASSERT_TRUE(ResolveRequestPath("", "snap_", false, &r).ok());
  EXPECT_EQ(r, "./snap_");
}

TEST(ResolveRequestPath, EscapesAreRefusedUnlessAllowed) {
  std::string r;
  for (const std::string req : {"/etc/cron.d/x", "../x", "a/../../x", "a/.."}) {
    EXPECT_FALSE(ResolveRequestPath("out", req, false, &r).ok()) << req;
    EXPECT_EQ(r, "out/") << req;
    ASSERT_TRUE(ResolveRequestPath("out", req, true, &r).ok()) << req;
    EXPECT_EQ(r, req);
  }
  // "..x" is a name, not a parent.
  ASSERT_TRUE(ResolveRequestPath("out", "..x", false, &r).ok());
  EXPECT_EQ(r, "out/..x");
}

// A NUL would cut the name where the file system sees it ("a/..\0b" looked like a
// name without "..", and opened "a/..").
TEST(ResolveRequestPath, ControlCharactersAreRefused) {
  std::string r;
  EXPECT_FALSE(ResolveRequestPath("out", std::string("a/..\0b", 6), true, &r).ok());
  EXPECT_FALSE(ResolveRequestPath("out", "snap\n", false, &r).ok());
  EXPECT_EQ(r, "out/");
}

}  // namespace
}  // namespace mbslam
