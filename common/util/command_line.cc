#include "common/util/command_line.h"

#include <cerrno>
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
      values_[a] = argv[++i];
    } else {
      values_[a] = "";
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
  return it == values_.end() ? fallback : it->second;
}

double CommandLineArgs::GetDouble(const std::string& key, double fallback) const {
  if (!Has(key)) return fallback;
  const std::string& v = values_.at(key);
  char* end = nullptr;
  errno = 0;
  const double d = v.empty() ? 0.0 : std::strtod(v.c_str(), &end);
  if (v.empty() || end != v.c_str() + v.size() || errno == ERANGE) {
    if (bad_number_.empty()) bad_number_ = "--" + key + " expects a number, got '" + v + "'";
    return fallback;
  }
  return d;
}

int64_t CommandLineArgs::GetInt(const std::string& key, int64_t fallback) const {
  if (!Has(key)) return fallback;
  const std::string& v = values_.at(key);
  char* end = nullptr;
  errno = 0;
  const long long n = v.empty() ? 0 : std::strtoll(v.c_str(), &end, 10);
  if (v.empty() || end != v.c_str() + v.size() || errno == ERANGE) {
    if (bad_number_.empty()) bad_number_ = "--" + key + " expects a whole number, got '" + v + "'";
    return fallback;
  }
  return static_cast<int64_t>(n);
}

std::string CommandLineArgs::Problems() const {
  if (!bad_.empty()) return bad_;
  if (!bad_number_.empty()) return bad_number_;
  for (const auto& [key, value] : values_) {
    if (!used_.count(key)) return "unknown option --" + key;
  }
  return "";
}

}  // namespace mbslam
