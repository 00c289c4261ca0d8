#include "common/util/command_line.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>

namespace mbslam {

CommandLineArgs::CommandLineArgs(int argc, const char* const* argv, int first) {
  for (int i = first; i < argc; ++i) {
    std::string a = argv[i];
    if (a.rfind("--", 0) != 0 || a.size() == 2) {
      bad_ = "unexpected argument '" + a + "'";
      return;
    }
    a = a.substr(2);
    if (i + 1 < argc && std::string(argv[i + 1]).rfind("--", 0) != 0) {
      values_[a].push_back(argv[++i]);
    } else {
      values_[a].push_back("");
    }
  }
}

bool CommandLineArgs::Has(const std::string& key) const {
  used_.insert(key);
  return values_.count(key) > 0;
}

std::string CommandLineArgs::Get(const std::string& key, const std::string& fallback) const {
  used_.insert(key);
  auto it = values_.find(key);
  return it == values_.end() ? fallback : it->second.back();
}

std::vector<std::string> CommandLineArgs::GetAll(const std::string& key) const {
  used_.insert(key);
  auto it = values_.find(key);
  return it == values_.end() ? std::vector<std::string>() : it->second;
}

template <typename T>
T CommandLineArgs::GetNumber(const std::string& key, T fallback,
                             Status (*parse)(const std::string&, const std::string&, T*)) const {
  if (!Has(key)) return fallback;
  T value = fallback;
  const Status st = parse(values_.at(key).back(), "--" + key, &value);
  if (!st.ok()) {
    if (bad_number_.empty()) bad_number_ = st.message();
    return fallback;
  }
  return value;
}

double CommandLineArgs::GetDouble(const std::string& key, double fallback) const {
  return GetNumber(key, fallback, &ParseDouble);
}

int64_t CommandLineArgs::GetInt(const std::string& key, int64_t fallback) const {
  return GetNumber(key, fallback, &ParseInt64);
}

std::string CommandLineArgs::ParseProblems() const { return !bad_.empty() ? bad_ : bad_number_; }

std::string CommandLineArgs::Problems() const {
  if (const std::string parse = ParseProblems(); !parse.empty()) return parse;
  for (const auto& [key, value] : values_) {
    if (!used_.count(key)) return "unknown option --" + key;
  }
  return "";
}

Status ParseDouble(const std::string& text, const std::string& what, double* value) {
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || end == nullptr || *end != '\0' || errno != 0 || !std::isfinite(v)) {
    return Status::Error(what + ": '" + text + "' is not a number");
  }
  *value = v;
  return Status::Ok();
}

Status ParseInt64(const std::string& text, const std::string& what, int64_t* value) {
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end == nullptr || *end != '\0' || errno != 0) {
    return Status::Error(what + ": '" + text + "' is not an integer");
  }
  *value = static_cast<int64_t>(v);
  return Status::Ok();
}

Status ParseImageSize(const std::string& text, const std::string& what, int* width, int* height) {
  const size_t x = text.find('x');
  auto digits = [](const std::string& t) {
    return !t.empty() && t.size() <= 5 && std::all_of(t.begin(), t.end(), [](char c) { return c >= '0' && c <= '9'; });
  };
  int64_t w = 0, h = 0;
  if (x == std::string::npos || !digits(text.substr(0, x)) || !digits(text.substr(x + 1)) ||
      !ParseInt64(text.substr(0, x), what, &w).ok() || !ParseInt64(text.substr(x + 1), what, &h).ok() || w < 1 ||
      h < 1 || w > 65535 || h > 65535) {
    return Status::Error(what + ": '" + text + "' is not WxH (two whole numbers 1-65535)");
  }
  *width = static_cast<int>(w);
  *height = static_cast<int>(h);
  return Status::Ok();
}

}  // namespace mbslam
