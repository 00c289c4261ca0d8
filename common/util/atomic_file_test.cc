#include "common/util/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>

#include "common/testing/temp_dir.h"

namespace mbslam {
namespace {

std::string TempDir() { return testing_util::MakeTestTempDir("atomic"); }

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

TEST(AtomicFile, RemovesOnlyTheTempFilesOfDeadWriters) {
  const std::string dir = TempDir();
  const pid_t child = fork();
  if (child == 0) _exit(0);
  int status = 0;
  waitpid(child, &status, 0);  // a writer that is gone
  const std::string dead = dir + "/map.ply.tmp." + std::to_string(child);
  const std::string alive = dir + "/map.ply.tmp." + std::to_string(getpid());
  const std::string parent = dir + "/map.ply.tmp." + std::to_string(getppid());
  const std::string other = dir + "/notes.tmp.txt";
  for (const std::string& p : {dead, alive, parent, other}) ASSERT_TRUE(WriteStringAtomically(p, "x").ok());
  EXPECT_EQ(RemoveStaleTempFiles(dir), 1);
  std::string text;
  EXPECT_FALSE(ReadFileToString(dead, &text).ok());
  EXPECT_TRUE(ReadFileToString(alive, &text).ok());
  EXPECT_TRUE(ReadFileToString(parent, &text).ok());
  EXPECT_TRUE(ReadFileToString(other, &text).ok());
}

}  // namespace
}  // namespace mbslam
