#ifndef MBSLAM_TEST_DRIVERS_PROCESS_UTIL_H_
#define MBSLAM_TEST_DRIVERS_PROCESS_UTIL_H_

// Running the driver executables from integration tests.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/testing/temp_dir.h"

namespace mbslam {
namespace testing_util {

// $MBSLAM_BIN_DIR/<name> (CTest sets it), else <build>/bin/<name> next to the
// <build>/tests folder this test runs from.
inline std::string BinPath(const std::string& name) {
  const char* dir = std::getenv("MBSLAM_BIN_DIR");
  if (dir && *dir) return std::string(dir) + "/" + name;
  char self[4096];
  const ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
  if (n > 0) {
    std::string path(self, static_cast<size_t>(n));
    path = path.substr(0, path.rfind('/'));          // <build>/tests
    path = path.substr(0, path.rfind('/')) + "/bin";  // <build>/bin
    return path + "/" + name;
  }
  return "build/bin/" + name;
}

inline std::string ReadWholeFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

struct ProcessResult {
  int exit_code = -1;  // -1 if it did not exit normally
  std::string out;
  std::string err;
};

// A child process with stdout and stderr going to temporary files (read by Wait(),
// removed by the destructor).
class ChildProcess {
 public:
  explicit ChildProcess(const std::vector<std::string>& argv) {
    out_path_ = TestTempRoot() + "/mbslam_proc_out_XXXXXX";
    err_path_ = TestTempRoot() + "/mbslam_proc_err_XXXXXX";
    const int out_fd = mkstemp(out_path_.data());
    const int err_fd = mkstemp(err_path_.data());
    pid_ = fork();
    if (pid_ == 0) {
      dup2(out_fd, STDOUT_FILENO);
      dup2(err_fd, STDERR_FILENO);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      execv(args[0], args.data());
      _exit(127);
    }
    close(out_fd);
    close(err_fd);
  }
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;
  ~ChildProcess() {
    if (!result_) Wait(0.0);
    // Removed here, the one place every ChildProcess passes through (Wait() may be
    // called by the test, or only by this destructor).
    unlink(out_path_.c_str());
    unlink(err_path_.c_str());
  }

  void Signal(int signal_number) { kill(pid_, signal_number); }

  // Waits up to timeout_s, then kills it (exit_code -1 then). Once the child is reaped,
  // later calls return the same result (its pid may belong to another process by then).
  ProcessResult Wait(double timeout_s) {
    if (result_) return *result_;
    ProcessResult result;
    int status = 0;
    bool done = false;
    const int steps = static_cast<int>(timeout_s * 100);
    for (int i = 0; i <= steps && !done; ++i) {
      if (waitpid(pid_, &status, WNOHANG) == pid_) {
        done = true;
      } else if (i < steps) {
        usleep(10000);
      }
    }
    if (!done) {
      kill(pid_, SIGKILL);
      waitpid(pid_, &status, 0);
    } else if (WIFEXITED(status)) {
      result.exit_code = WEXITSTATUS(status);
    }
    result.out = ReadWholeFile(out_path_);
    result.err = ReadWholeFile(err_path_);
    result_ = result;
    return result;
  }

 private:
  pid_t pid_ = -1;
  std::optional<ProcessResult> result_;  // of the first Wait(): the child is reaped
  std::string out_path_, err_path_;
};

// Runs argv[0] with the arguments, stdout and stderr captured, killed after
// timeout_s (exit_code -1 then).
inline ProcessResult RunProcess(const std::vector<std::string>& argv, double timeout_s = 60.0) {
  ChildProcess child(argv);
  return child.Wait(timeout_s);
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_TEST_DRIVERS_PROCESS_UTIL_H_
