#include "drivers/common/command_line.h"

namespace mbslam {

Status CommandLine::Parse(int argc, const char* const* argv, const std::set<std::string>& flags,
                          const std::set<std::string>& valued, CommandLine* out) {
  *out = CommandLine();
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--", 0) != 0 || arg == "--") {
      out->positional_.push_back(arg);
      continue;
    }
    std::string name = arg.substr(2);
    std::string value;
    bool has_value = false;
    const size_t eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
      has_value = true;
    }
    if (flags.count(name)) {
      if (has_value) return Status::Error("option --" + name + " takes no value");
      out->values_[name].push_back("");
    } else if (valued.count(name)) {
      if (!has_value) {
        if (i + 1 >= argc) return Status::Error("option --" + name + " needs a value");
        value = argv[++i];
      }
      out->values_[name].push_back(value);
    } else {
      return Status::Error("unknown option --" + name + " (try --help)");
    }
  }
  return Status::Ok();
}

std::string CommandLine::Get(const std::string& name, const std::string& fallback) const {
  auto it = values_.find(name);
  if (it == values_.end() || it->second.empty()) return fallback;
  return it->second.back();
}

std::vector<std::string> CommandLine::GetAll(const std::string& name) const {
  auto it = values_.find(name);
  if (it == values_.end()) return {};
  return it->second;
}

Status ParseOptionAssignment(const std::string& assignment, YAML::Node* root) {
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) {
    return Status::Error("expected key.path=value, got '" + assignment + "'");
  }
  const std::string path = assignment.substr(0, eq);
  const std::string text = assignment.substr(eq + 1);
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return Status::Error("bad value in '" + assignment + "': " + e.what());
  }
  if (text.empty()) value = YAML::Node(std::string());
  std::vector<std::string> keys;
  size_t start = 0;
  while (true) {
    const size_t dot = path.find('.', start);
    const std::string key = path.substr(start, dot == std::string::npos ? dot : dot - start);
    if (key.empty()) return Status::Error("empty key in '" + assignment + "'");
    keys.push_back(key);
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  YAML::Node node = value;
  for (auto it = keys.rbegin(); it != keys.rend(); ++it) {
    YAML::Node parent(YAML::NodeType::Map);
    parent[*it] = node;
    node = parent;
  }
  *root = node;
  return Status::Ok();
}

}  // namespace mbslam
