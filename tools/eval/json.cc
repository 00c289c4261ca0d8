#include "tools/eval/json.h"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace mbslam {
namespace eval {

Json::Json(const std::vector<double>& values) : type_(Type::kArray) {
  for (double v : values) {
    array_.emplace_back(v);
  }
}

Json& Json::Set(const std::string& key, Json value) {
  if (type_ == Type::kNull) {
    type_ = Type::kObject;
  }
  for (auto& m : members_) {
    if (m.first == key) {
      m.second = std::move(value);
      return *this;
    }
  }
  members_.emplace_back(key, std::move(value));
  return *this;
}

Json& Json::Push(Json value) {
  if (type_ == Type::kNull) {
    type_ = Type::kArray;
  }
  array_.push_back(std::move(value));
  return *this;
}

const Json* Json::Find(const std::string& key) const {
  if (type_ != Type::kObject) {
    return nullptr;
  }
  for (const auto& m : members_) {
    if (m.first == key) {
      return &m.second;
    }
  }
  return nullptr;
}

double Json::AsDouble() const {
  if (type_ == Type::kInt) {
    return static_cast<double>(int_);
  }
  if (type_ == Type::kDouble) {
    return double_;
  }
  if (type_ == Type::kBool) {
    return bool_ ? 1.0 : 0.0;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

namespace {

void AppendEscaped(const std::string& s, std::string* out) {
  out->push_back('"');
  for (char c : s) {
    switch (c) {
      case '"':
        *out += "\\\"";
        break;
      case '\\':
        *out += "\\\\";
        break;
      case '\n':
        *out += "\\n";
        break;
      case '\t':
        *out += "\\t";
        break;
      case '\r':
        *out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof(buf), "\\u%04x", c);
          *out += buf;
        } else {
          out->push_back(c);
        }
    }
  }
  out->push_back('"');
}

}  // namespace

void Json::DumpTo(std::string* out) const {
  switch (type_) {
    case Type::kNull:
      *out += "null";
      break;
    case Type::kBool:
      *out += bool_ ? "true" : "false";
      break;
    case Type::kInt:
      *out += std::to_string(int_);
      break;
    case Type::kDouble: {
      if (!std::isfinite(double_)) {
        *out += "null";
      } else {
        // Shortest of %.15g / %.17g that reads back as the same double.
        char buf[32];
        std::snprintf(buf, sizeof(buf), "%.15g", double_);
        if (std::strtod(buf, nullptr) != double_) {
          std::snprintf(buf, sizeof(buf), "%.17g", double_);
        }
        *out += buf;
      }
      break;
    }
    case Type::kString:
      AppendEscaped(string_, out);
      break;
    case Type::kArray:
      out->push_back('[');
      for (size_t i = 0; i < array_.size(); ++i) {
        if (i) {
          *out += ", ";
        }
        array_[i].DumpTo(out);
      }
      out->push_back(']');
      break;
    case Type::kObject:
      out->push_back('{');
      for (size_t i = 0; i < members_.size(); ++i) {
        if (i) {
          *out += ", ";
        }
        AppendEscaped(members_[i].first, out);
        *out += ": ";
        members_[i].second.DumpTo(out);
      }
      out->push_back('}');
      break;
  }
}

std::string Json::Dump() const {
  std::string out;
  DumpTo(&out);
  return out;
}

namespace {

class Parser {
 public:
  explicit Parser(const std::string& text) : s_(text) {}

  bool ParseDocument(Json* out, std::string* error) {
    const bool ok = ParseValue(out) && (SkipSpace(), pos_ == s_.size());
    if (!ok && error) {
      *error = "JSON parse error at offset " + std::to_string(pos_);
    }
    return ok;
  }

 private:
  void SkipSpace() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) {
      ++pos_;
    }
  }
  bool Literal(const char* lit) {
    const std::string l(lit);
    if (s_.compare(pos_, l.size(), l) != 0) {
      return false;
    }
    pos_ += l.size();
    return true;
  }
  bool ParseString(std::string* out) {
    if (pos_ >= s_.size() || s_[pos_] != '"') {
      return false;
    }
    ++pos_;
    while (pos_ < s_.size() && s_[pos_] != '"') {
      char c = s_[pos_++];
      if (c == '\\') {
        if (pos_ >= s_.size()) {
          return false;
        }
        const char e = s_[pos_++];
        switch (e) {
          case 'n':
            c = '\n';
            break;
          case 't':
            c = '\t';
            break;
          case 'r':
            c = '\r';
            break;
          case 'b':
            c = '\b';
            break;
          case 'f':
            c = '\f';
            break;
          case 'u': {
            if (pos_ + 4 > s_.size()) {
              return false;
            }
            c = static_cast<char>(std::strtol(s_.substr(pos_, 4).c_str(), nullptr, 16));
            pos_ += 4;
            break;
          }
          default:
            c = e;
        }
      }
      out->push_back(c);
    }
    if (pos_ >= s_.size()) {
      return false;
    }
    ++pos_;
    return true;
  }
  bool ParseValue(Json* out) {
    SkipSpace();
    if (pos_ >= s_.size()) {
      return false;
    }
    const char c = s_[pos_];
    if (c == '{') {
      ++pos_;
      *out = Json::Object();
      SkipSpace();
      if (pos_ < s_.size() && s_[pos_] == '}') {
        return ++pos_, true;
      }
      while (true) {
        SkipSpace();
        std::string key;
        if (!ParseString(&key)) {
          return false;
        }
        SkipSpace();
        if (pos_ >= s_.size() || s_[pos_] != ':') {
          return false;
        }
        ++pos_;
        Json value;
        if (!ParseValue(&value)) {
          return false;
        }
        out->Set(key, std::move(value));
        SkipSpace();
        if (pos_ < s_.size() && s_[pos_] == ',') {
          ++pos_;
          continue;
        }
        if (pos_ < s_.size() && s_[pos_] == '}') {
          return ++pos_, true;
        }
        return false;
      }
    }
    if (c == '[') {
      ++pos_;
      *out = Json::Array();
      SkipSpace();
      if (pos_ < s_.size() && s_[pos_] == ']') {
        return ++pos_, true;
      }
      while (true) {
        Json value;
        if (!ParseValue(&value)) {
          return false;
        }
        out->Push(std::move(value));
        SkipSpace();
        if (pos_ < s_.size() && s_[pos_] == ',') {
          ++pos_;
          continue;
        }
        if (pos_ < s_.size() && s_[pos_] == ']') {
          return ++pos_, true;
        }
        return false;
      }
    }
    if (c == '"') {
      std::string str;
      if (!ParseString(&str)) {
        return false;
      }
      *out = Json(std::move(str));
      return true;
    }
    if (Literal("true")) {
      return *out = Json(true), true;
    }
    if (Literal("false")) {
      return *out = Json(false), true;
    }
    if (Literal("null")) {
      return *out = Json(), true;
    }
    const char* begin = s_.c_str() + pos_;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin) {
      return false;
    }
    const std::string token(begin, static_cast<size_t>(end - begin));
    pos_ += token.size();
    if (token.find_first_of(".eE") == std::string::npos) {
      *out = Json(static_cast<int64_t>(std::strtoll(token.c_str(), nullptr, 10)));
    } else {
      *out = Json(v);
    }
    return true;
  }

  const std::string& s_;
  size_t pos_ = 0;
};

}  // namespace

bool Json::Parse(const std::string& text, Json* out, std::string* error) {
  Parser parser(text);
  return parser.ParseDocument(out, error);
}

}  // namespace eval
}  // namespace mbslam
