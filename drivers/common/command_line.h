#ifndef MBSLAM_DRIVERS_COMMON_COMMAND_LINE_H_
#define MBSLAM_DRIVERS_COMMON_COMMAND_LINE_H_

// A small command-line parser for the driver executables, and `--set a.b=value`
// overrides of any options field (parsed as YAML, checked like the option file).

#include <yaml-cpp/yaml.h>

#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/config/options_yaml.h"
#include "common/util/command_line.h"  // ParseDouble, ParseInt64
#include "common/util/status.h"

namespace mbslam {

class CommandLine {
 public:
  // Accepts "--name value", "--name=value" for names in `valued` (repeatable) and
  // "--name" for names in `flags`. Anything else not starting with "--" is positional.
  static Status Parse(int argc, const char* const* argv, const std::set<std::string>& flags,
                      const std::set<std::string>& valued, CommandLine* out);

  bool Has(const std::string& name) const { return values_.count(name) > 0; }
  // Last value given for `name`, or `fallback`.
  std::string Get(const std::string& name, const std::string& fallback = "") const;
  // All values given for a repeatable option, in order.
  std::vector<std::string> GetAll(const std::string& name) const;
  const std::vector<std::string>& positional() const { return positional_; }

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::vector<std::string> positional_;
};

// Builds {a: {b: value}} from "a.b=value" (value parsed as YAML, so "[1, 2]" is a list).
Status ParseOptionAssignment(const std::string& assignment, YAML::Node* root);

// Applies "a.b=value" to an options struct; fails on unknown keys, bad values and a
// failed Check(), leaving `options` unchanged.
template <typename T>
Status ApplyOptionAssignment(const std::string& assignment, T* options) {
  YAML::Node root;
  MBSLAM_RETURN_IF_ERROR(ParseOptionAssignment(assignment, &root));
  return LoadOptionsFromYaml(root, "", options).WithContext("--set " + assignment);
}

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_COMMAND_LINE_H_
