#ifndef MBSLAM_TEST_DRIVERS_PROCESS_UTIL_H_
#define MBSLAM_TEST_DRIVERS_PROCESS_UTIL_H_

// Running the driver executables from integration tests.

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace mbslam {
namespace testing_util {

// $MBSLAM_BIN_DIR/<name> (CTest sets it), else build/bin/<name>.
inline std::string BinPath(const std::string& name) {
  const char* dir = std::getenv("MBSLAM_BIN_DIR");
  return std::string(dir && *dir ? dir : "build/bin") + "/" + name;
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

// Runs argv[0] with the arguments, stdout and stderr captured, killed after
// timeout_s (exit_code -1 then).
inline ProcessResult RunProcess(const std::vector<std::string>& argv, double timeout_s = 60.0) {
  ProcessResult result;
  char out_name[] = "/tmp/mbslam_proc_out_XXXXXX";
  char err_name[] = "/tmp/mbslam_proc_err_XXXXXX";
  const int out_fd = mkstemp(out_name);
  const int err_fd = mkstemp(err_name);
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out_fd, STDOUT_FILENO);
    dup2(err_fd, STDERR_FILENO);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  const int steps = static_cast<int>(timeout_s * 100);
  bool done = false;
  for (int i = 0; i < steps && !done; ++i) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      done = true;
    } else {
      usleep(10000);
    }
  }
  if (!done) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  } else if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  }
  close(out_fd);
  close(err_fd);
  result.out = ReadWholeFile(out_name);
  result.err = ReadWholeFile(err_name);
  unlink(out_name);
  unlink(err_name);
  return result;
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_TEST_DRIVERS_PROCESS_UTIL_H_
