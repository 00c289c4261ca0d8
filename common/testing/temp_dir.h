#ifndef MBSLAM_COMMON_TESTING_TEMP_DIR_H_
#define MBSLAM_COMMON_TESTING_TEMP_DIR_H_

// Temporary folders for tests (header only: nothing to link, usable from every layer's
// tests). MakeTestTempDir makes $TMPDIR/mbslam_<tag>_XXXXXX (/tmp without $TMPDIR) and
// removes it, with everything in it, when the process that made it exits normally
// (main returns or exit() is called; a crash, a signal or _exit() leaves it). Before
// this, every test run left its folders in /tmp.
//
// Only the process that made a folder removes it: tests fork children (writers killed
// by the crash-safety test, the driver tests' ChildProcess before its exec), and a child
// that calls exit() runs the exit handlers it inherited, which must not delete folders
// its parent is still using.
//
// MBSLAM_KEEP_TEST_DIRS=1 (any non-empty value) keeps the folders and prints where they
// are, to look at what a failing test wrote.

#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace mbslam {
namespace testing_util {

// Where tests put temporary files: $TMPDIR, else /tmp.
inline std::string TestTempRoot() {
  const char* tmp = std::getenv("TMPDIR");
  return tmp && *tmp ? std::string(tmp) : std::string("/tmp");
}

namespace temp_dir_internal {

struct Registry {
  std::mutex mutex;
  std::vector<std::pair<pid_t, std::string>> dirs;  // (the process that made it, folder)
};

inline Registry& GetRegistry();

// The exit handler (std::atexit).
inline void RemoveTestTempDirs() {
  Registry& registry = GetRegistry();
  // try_lock: a child forked while another thread of its parent held the lock would
  // otherwise hang in exit(); such a child owns no folder anyway.
  std::unique_lock<std::mutex> lock(registry.mutex, std::try_to_lock);
  if (!lock.owns_lock()) return;
  const char* keep = std::getenv("MBSLAM_KEEP_TEST_DIRS");
  const bool keep_dirs = keep && *keep;
  const pid_t self = ::getpid();
  for (const auto& [pid, dir] : registry.dirs) {
    if (pid != self) continue;
    if (keep_dirs) {
      std::fprintf(stderr, "MBSLAM_KEEP_TEST_DIRS: keeping %s\n", dir.c_str());
      continue;
    }
    std::error_code ec;  // best effort: a folder already gone is fine
    std::filesystem::remove_all(dir, ec);
  }
}

// Never destroyed: the exit handler must find it whatever order static destructors and
// exit handlers run in. The handler is registered when it is made, i.e. with the first
// folder.
inline Registry& GetRegistry() {
  static Registry* const registry = [] {
    Registry* r = new Registry;
    std::atexit(&RemoveTestTempDirs);
    return r;
  }();
  return *registry;
}

}  // namespace temp_dir_internal

// A new, empty folder $TMPDIR/mbslam_<tag>_XXXXXX, removed at the normal exit of this
// process (see the top of the file). Aborts the test (the reason on stderr) when it
// cannot be made: the callers append file names to it, and "" would have them write to
// the filesystem's root.
inline std::string MakeTestTempDir(const std::string& tag) {
  std::string pattern = TestTempRoot() + "/mbslam_" + tag + "_XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) {
    std::fprintf(stderr, "MakeTestTempDir: cannot make %s: %s\n", pattern.c_str(),
                 std::strerror(errno));
    std::abort();
  }
  temp_dir_internal::Registry& registry = temp_dir_internal::GetRegistry();
  std::lock_guard<std::mutex> lock(registry.mutex);
  registry.dirs.emplace_back(::getpid(), pattern);
  return pattern;
}

// The path of `name` in a new such folder.
inline std::string MakeTestTempPath(const std::string& tag, const std::string& name) {
  return MakeTestTempDir(tag) + "/" + name;
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_COMMON_TESTING_TEMP_DIR_H_
