#include "common/config/options_yaml.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "common/util/atomic_file.h"

namespace mbslam {
namespace internal {
namespace {

Status TypeError(const std::string& path, const YAML::Node& node, const char* expected) {
  std::string got = node.IsScalar() ? "'" + node.Scalar() + "'"
                    : node.IsSequence() ? std::string("a list")
                    : node.IsMap() ? std::string("a mapping") : std::string("nothing");
  return Status::Error("option '" + path + "': expected " + expected + ", got " + got);
}

bool ParseDoubleText(const std::string& text, double* value) {
  if (text.empty()) return false;
  const char* begin = text.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (end == begin || *end != '\0') return false;
  *value = v;
  return true;
}

bool ParseIntText(const std::string& text, int64_t* value) {
  if (text.empty()) return false;
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const long long v = std::strtoll(begin, &end, 10);
  if (end == begin || *end != '\0' || errno == ERANGE) return false;
  *value = static_cast<int64_t>(v);
  return true;
}

}  // namespace

std::string JoinPath(const std::string& prefix, const char* name) {
  return prefix.empty() ? std::string(name) : prefix + "." + name;
}

std::string Sorted(const std::set<std::string>& names) {
  std::string out;
  for (const auto& n : names) {
    if (!out.empty()) out += ", ";
    out += n;
  }
  return out;
}

Status ParseScalar(const YAML::Node& node, const std::string& path, bool* value) {
  if (!node.IsScalar()) return TypeError(path, node, "true or false");
  const std::string& s = node.Scalar();
  if (s == "true" || s == "True" || s == "TRUE" || s == "yes" || s == "on") {
    *value = true;
  } else if (s == "false" || s == "False" || s == "FALSE" || s == "no" || s == "off") {
    *value = false;
  } else {
    return TypeError(path, node, "true or false");
  }
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path, int64_t* value) {
  int64_t v = 0;
  if (!node.IsScalar() || !ParseIntText(node.Scalar(), &v)) {
    return TypeError(path, node, "an integer");
  }
  *value = v;
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path, int* value) {
  int64_t v = 0;
  MBSLAM_RETURN_IF_ERROR(ParseScalar(node, path, &v));
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    return TypeError(path, node, "a 32-bit integer");
  }
  *value = static_cast<int>(v);
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path, double* value) {
  double v = 0.0;
  if (!node.IsScalar() || !ParseDoubleText(node.Scalar(), &v)) {
    return TypeError(path, node, "a number");
  }
  if (!std::isfinite(v)) return TypeError(path, node, "a finite number");
  *value = v;
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path, float* value) {
  double v = 0.0;
  MBSLAM_RETURN_IF_ERROR(ParseScalar(node, path, &v));
  if (std::fabs(v) > std::numeric_limits<float>::max()) {
    return TypeError(path, node, "a number in float range");
  }
  *value = static_cast<float>(v);
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path, std::string* value) {
  if (!node.IsScalar()) return TypeError(path, node, "a string");
  *value = node.Scalar();
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path, std::vector<double>* value) {
  if (!node.IsSequence()) return TypeError(path, node, "a list of numbers");
  std::vector<double> out;
  for (size_t i = 0; i < node.size(); ++i) {
    double v = 0.0;
    MBSLAM_RETURN_IF_ERROR(ParseScalar(node[i], path + "[" + std::to_string(i) + "]", &v));
    out.push_back(v);
  }
  *value = std::move(out);
  return Status::Ok();
}

Status ParseScalar(const YAML::Node& node, const std::string& path,
                   std::vector<std::string>* value) {
  if (!node.IsSequence()) return TypeError(path, node, "a list of strings");
  std::vector<std::string> out;
  for (size_t i = 0; i < node.size(); ++i) {
    std::string v;
    MBSLAM_RETURN_IF_ERROR(ParseScalar(node[i], path + "[" + std::to_string(i) + "]", &v));
    out.push_back(v);
  }
  *value = std::move(out);
  return Status::Ok();
}

Status ParseDoubleArray(const YAML::Node& node, const std::string& path, double* values,
                        size_t count) {
  std::vector<double> v;
  MBSLAM_RETURN_IF_ERROR(ParseScalar(node, path, &v));
  if (v.size() != count) {
    return Status::Error("option '" + path + "': expected a list of " + std::to_string(count) +
                         " numbers, got " + std::to_string(v.size()));
  }
  for (size_t i = 0; i < count; ++i) values[i] = v[i];
  return Status::Ok();
}

std::string FormatScalar(bool value) { return value ? "true" : "false"; }
std::string FormatScalar(int value) { return std::to_string(value); }
std::string FormatScalar(int64_t value) { return std::to_string(value); }

std::string FormatScalar(double value) {
  // Shortest representation that reads back exactly.
  char buf[64];
  for (int precision = 6; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof(buf), "%.*g", precision, value);
    if (std::strtod(buf, nullptr) == value) break;
  }
  std::string s = buf;
  // Keep a decimal point so the value reads as a number of the same kind.
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string FormatScalar(float value) { return FormatScalar(static_cast<double>(value)); }

std::string FormatScalar(const std::string& value) {
  YAML::Emitter emitter;
  emitter << YAML::DoubleQuoted << value;
  return emitter.c_str();
}

std::string FormatScalar(const std::vector<double>& value) {
  return FormatDoubleArray(value.data(), value.size());
}

std::string FormatScalar(const std::vector<std::string>& value) {
  std::string out = "[";
  for (size_t i = 0; i < value.size(); ++i) {
    if (i) out += ", ";
    out += FormatScalar(value[i]);
  }
  return out + "]";
}

std::string FormatDoubleArray(const double* values, size_t count) {
  std::string out = "[";
  for (size_t i = 0; i < count; ++i) {
    if (i) out += ", ";
    out += FormatScalar(values[i]);
  }
  return out + "]";
}

}  // namespace internal

Status CheckYamlTextIsUtf8(const std::string& text, const std::string& what) {
  const auto* p = reinterpret_cast<const unsigned char*>(text.data());
  const size_t n = text.size();
  size_t line = 1;
  for (size_t i = 0; i < n;) {
    const unsigned char c = p[i];
    if (c < 0x80) {
      if (c == '\n') ++line;
      ++i;
      continue;
    }
    // Lead byte: the number of continuation bytes and the smallest code point that
    // needs them (shorter encodings are overlong).
    size_t extra = 0;
    uint32_t min = 0;
    if ((c & 0xE0) == 0xC0) {
      extra = 1;
      min = 0x80;
    } else if ((c & 0xF0) == 0xE0) {
      extra = 2;
      min = 0x800;
    } else if ((c & 0xF8) == 0xF0) {
      extra = 3;
      min = 0x10000;
    }
    bool ok = extra > 0 && n - i > extra;
    uint32_t code = c & (0x3Fu >> extra);
    for (size_t k = 1; ok && k <= extra; ++k) {
      ok = (p[i + k] & 0xC0) == 0x80;
      code = (code << 6) | (p[i + k] & 0x3Fu);
    }
    ok = ok && code >= min && code <= 0x10FFFF && !(code >= 0xD800 && code <= 0xDFFF);
    if (!ok) {
      return Status::Error(what + ": line " + std::to_string(line) +
                           " is not UTF-8 text (YAML must be UTF-8)");
    }
    i += extra + 1;
  }
  return Status::Ok();
}

Status ReadYamlFile(const std::string& path, YAML::Node* root) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text, size_t{16} << 20));
  MBSLAM_RETURN_IF_ERROR(CheckYamlTextIsUtf8(text, path));
  try {
    *root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return Status::Error(path + ": YAML syntax error: " + e.what());
  }
  return Status::Ok();
}

}  // namespace mbslam
