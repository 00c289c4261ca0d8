#include "common/util/atomic_file.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

namespace mbslam {
namespace {

std::string TempDir() {
  char pattern[] = "/tmp/mbslam_atomic_XXXXXX";
  return mkdtemp(pattern);
}

TEST(AtomicFile, WritesAndReplaces) {
  const std::string path = TempDir() + "/f.txt";
  ASSERT_TRUE(WriteStringAtomically(path, "first").ok());
  std::string text;
  ASSERT_TRUE(ReadFileToString(path, &text).ok());
  EXPECT_EQ(text, "first");
  ASSERT_TRUE(WriteStringAtomically(path, "second").ok());
  ASSERT_TRUE(ReadFileToString(path, &text).ok());
  EXPECT_EQ(text, "second");
}

TEST(AtomicFile, FailedWriterLeavesOldFileIntact) {
  const std::string path = TempDir() + "/f.txt";
  ASSERT_TRUE(WriteStringAtomically(path, "old").ok());
  const Status status = WriteFileAtomically(path, [](std::ostream& out) {
    out << "partial";
    return false;  // the writer gives up half way
  });
  EXPECT_FALSE(status.ok());
  std::string text;
  ASSERT_TRUE(ReadFileToString(path, &text).ok());
  EXPECT_EQ(text, "old");
  EXPECT_NE(access((path + ".tmp." + std::to_string(getpid())).c_str(), F_OK), 0);
}

TEST(AtomicFile, ReadRespectsLimitAndMissingFile) {
  const std::string path = TempDir() + "/big.txt";
  ASSERT_TRUE(WriteStringAtomically(path, std::string(100, 'x')).ok());
  std::string text;
  EXPECT_FALSE(ReadFileToString(path, &text, 10).ok());
  EXPECT_FALSE(ReadFileToString(path + ".missing", &text).ok());
}

}  // namespace
}  // namespace mbslam
