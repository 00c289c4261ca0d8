#ifndef MBSLAM_TEST_TOOLS_RUN_COMMAND_H_
#define MBSLAM_TEST_TOOLS_RUN_COMMAND_H_

// Running the project's executables from tests (header only): where they are, a command's
// exit status and stdout, and the last line of that output (where the tools print their
// JSON).

#include <sys/wait.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "test/drivers/process_util.h"

namespace mbslam {
namespace testing_util {

// The executable `name`: $MBSLAM_BIN_DIR (set by CTest), else the build's bin folder
// (BinPath of the driver tests).
inline std::string ToolPath(const std::string& name) { return BinPath(name); }

// Runs `command` through the shell; its exit status (-1 if it could not run or did not
// exit), its stdout in `out`.
inline int RunCommand(const std::string& command, std::string* out) {
  out->clear();
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return -1;
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof(buf), pipe)) out->append(buf, n);
  const int status = pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The last non-empty line of `text` (without its newline).
inline std::string LastLine(std::string text) {
  while (!text.empty() && text.back() == '\n') text.pop_back();
  const size_t nl = text.rfind('\n');
  return nl == std::string::npos ? text : text.substr(nl + 1);
}

}  // namespace testing_util
}  // namespace mbslam

#endif  // MBSLAM_TEST_TOOLS_RUN_COMMAND_H_
