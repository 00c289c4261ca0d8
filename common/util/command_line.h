#ifndef MBSLAM_COMMON_UTIL_COMMAND_LINE_H_
#define MBSLAM_COMMON_UTIL_COMMAND_LINE_H_

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/util/status.h"

namespace mbslam {

// Parses a whole, finite number; fails with a message naming `what` on anything else
// (trailing text, empty, out of range, inf / nan).
Status ParseDouble(const std::string& text, const std::string& what, double* value);
Status ParseInt64(const std::string& text, const std::string& what, int64_t* value);
// "WxH": two whole numbers 1-65535 and nothing else (e.g. 640x480).
Status ParseImageSize(const std::string& text, const std::string& what, int* width, int* height);

// The command line of the project's tools: `--key value` pairs and bare `--flag`s (a
// flag is followed by another `--key` or by nothing; a value may start with a single
// '-', e.g. a negative number). Every key read is remembered: Problems() then names the
// first argument that is not an option, the first number that does not parse, or the
// first option no one asked for.
class CommandLineArgs {
 public:
  // Arguments argv[first] ... argv[argc - 1] (a subcommand before them is the caller's).
  CommandLineArgs(int argc, const char* const* argv, int first = 1);

  bool Has(const std::string& key) const;
  // The value ("" for a bare flag), or `fallback` when the option is absent; an option
  // given more than once: its last value.
  std::string Get(const std::string& key, const std::string& fallback = "") const;
  // Every value of an option given more than once, in order (none when absent).
  std::vector<std::string> GetAll(const std::string& key) const;
  // The value as a number, or `fallback` when absent; a value ParseDouble / ParseInt64
  // refuses also gives `fallback` and is a problem.
  double GetDouble(const std::string& key, double fallback) const;
  int64_t GetInt(const std::string& key, int64_t fallback) const;
  // The first problem with the command line ("" if none).
  std::string Problems() const;
  // The same without the unknown-option check: a malformed command line or a number read
  // so far that did not parse. A tool checks it once its numbers are read, before any
  // work, and Problems() at the end.
  std::string ParseProblems() const;

 private:
  // The value parsed by `parse`, or `fallback` (absent, or a problem when it does not parse).
  template <typename T>
  T GetNumber(const std::string& key, T fallback,
              Status (*parse)(const std::string&, const std::string&, T*)) const;

  std::map<std::string, std::vector<std::string>> values_;
  mutable std::set<std::string> used_;
  std::string bad_;                  // a malformed command line
  mutable std::string bad_number_;   // the first value that did not parse
};

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_COMMAND_LINE_H_
