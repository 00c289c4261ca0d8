#include "common/lcm/wire_check.h"

#include <cctype>
#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

#include "common/lcm/lcm_schemas_embed.h"

namespace mbslam {
namespace {

enum class Kind { kInt8, kInt16, kInt32, kInt64, kFloat, kDouble, kByte, kBool, kString, kStruct };

struct Dim {
  int64_t fixed = -1;      // fixed length, or -1
  int length_field = -1;   // index of an earlier integer field holding the length
};

struct Field {
  std::string name;
  Kind kind = Kind::kInt8;
  std::string struct_name;  // for kStruct
  std::vector<Dim> dims;
};

struct Schema {
  std::string name;
  std::vector<Field> fields;
};

// ---- a parser for the subset of the LCM type language this project uses ----

class Lexer {
 public:
  explicit Lexer(const std::string& text) : text_(text) {}

  // Returns the next token ("" at the end): identifiers, numbers, punctuation.
  std::string Next() {
    SkipSpaceAndComments();
    if (pos_ >= text_.size()) return "";
    const char c = text_[pos_];
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '.' || c == '-' ||
        c == '+') {
      size_t start = pos_;
      while (pos_ < text_.size() &&
             (std::isalnum(static_cast<unsigned char>(text_[pos_])) || text_[pos_] == '_' ||
              text_[pos_] == '.' || text_[pos_] == '-' || text_[pos_] == '+')) {
        ++pos_;
      }
      return text_.substr(start, pos_ - start);
    }
    ++pos_;
    return std::string(1, c);
  }

 private:
  void SkipSpaceAndComments() {
    while (pos_ < text_.size()) {
      if (std::isspace(static_cast<unsigned char>(text_[pos_]))) {
        ++pos_;
      } else if (text_.compare(pos_, 2, "//") == 0) {
        while (pos_ < text_.size() && text_[pos_] != '\n') ++pos_;
      } else if (text_.compare(pos_, 2, "/*") == 0) {
        const size_t end = text_.find("*/", pos_ + 2);
        pos_ = end == std::string::npos ? text_.size() : end + 2;
      } else {
        break;
      }
    }
  }
  const std::string& text_;
  size_t pos_ = 0;
};

bool PrimitiveKind(const std::string& t, Kind* kind) {
  static const std::map<std::string, Kind> kinds = {
      {"int8_t", Kind::kInt8},   {"int16_t", Kind::kInt16}, {"int32_t", Kind::kInt32},
      {"int64_t", Kind::kInt64}, {"float", Kind::kFloat},   {"double", Kind::kDouble},
      {"byte", Kind::kByte},     {"boolean", Kind::kBool},  {"string", Kind::kString}};
  auto it = kinds.find(t);
  if (it == kinds.end()) return false;
  *kind = it->second;
  return true;
}

std::map<std::string, Schema> ParseSchemas(const std::string& text) {
  std::map<std::string, Schema> schemas;
  Lexer lex(text);
  for (std::string tok = lex.Next(); !tok.empty(); tok = lex.Next()) {
    if (tok == "package") {
      lex.Next();  // name
      lex.Next();  // ;
      continue;
    }
    if (tok != "struct") continue;
    Schema schema;
    schema.name = lex.Next();
    lex.Next();  // {
    for (std::string t = lex.Next(); !t.empty() && t != "}"; t = lex.Next()) {
      if (t == "const") {  // const type NAME = value (, NAME = value)* ;
        while (!t.empty() && t != ";") t = lex.Next();
        continue;
      }
      Field field;
      if (!PrimitiveKind(t, &field.kind)) {
        field.kind = Kind::kStruct;
        const size_t dot = t.rfind('.');
        field.struct_name = dot == std::string::npos ? t : t.substr(dot + 1);
      }
      field.name = lex.Next();
      for (std::string d = lex.Next(); d == "["; d = lex.Next()) {
        const std::string len = lex.Next();
        lex.Next();  // ]
        Dim dim;
        if (std::isdigit(static_cast<unsigned char>(len[0]))) {
          dim.fixed = std::stoll(len);
        } else {
          for (size_t i = 0; i < schema.fields.size(); ++i) {
            if (schema.fields[i].name == len) dim.length_field = static_cast<int>(i);
          }
        }
        field.dims.push_back(dim);
        // the token after ']' is consumed by the loop header: '[' or ';'
      }
      schema.fields.push_back(std::move(field));
    }
    schemas[schema.name] = std::move(schema);
  }
  return schemas;
}

const std::map<std::string, Schema>& Schemas() {
  static const std::map<std::string, Schema>* schemas =
      new std::map<std::string, Schema>(ParseSchemas(kLcmSchemaText));
  return *schemas;
}

// ---- the walker ----

class Walker {
 public:
  Walker(const uint8_t* data, size_t size) : data_(data), size_(size) {}

  Status WalkStruct(const Schema& schema, int depth) {
    if (depth > 8) return Status::Error("nesting too deep");
    std::vector<int64_t> values(schema.fields.size(), 0);
    for (size_t i = 0; i < schema.fields.size(); ++i) {
      const Field& f = schema.fields[i];
      int64_t count = 1;
      for (const Dim& d : f.dims) {
        int64_t n = d.fixed;
        if (d.length_field >= 0) n = values[static_cast<size_t>(d.length_field)];
        if (n < 0) {
          return Status::Error(schema.name + "." + f.name + ": negative length " +
                               std::to_string(n));
        }
        // Every element takes at least one byte: no count can exceed the rest.
        if (n > static_cast<int64_t>(remaining()) && n > 0) {
          return Status::Error(schema.name + "." + f.name + ": length " + std::to_string(n) +
                               " exceeds the " + std::to_string(remaining()) +
                               " bytes left in the message");
        }
        count *= n;
        if (count > static_cast<int64_t>(remaining()) && count > 0 && f.kind != Kind::kStruct) {
          return Status::Error(schema.name + "." + f.name + ": " + std::to_string(count) +
                               " elements exceed the bytes left in the message");
        }
      }
      if (f.kind == Kind::kStruct) {
        auto it = Schemas().find(f.struct_name);
        if (it == Schemas().end()) return Status::Error("unknown nested type " + f.struct_name);
        for (int64_t k = 0; k < count; ++k) MBSLAM_RETURN_IF_ERROR(WalkStruct(it->second, depth + 1));
        continue;
      }
      if (f.kind == Kind::kString) {
        for (int64_t k = 0; k < count; ++k) MBSLAM_RETURN_IF_ERROR(WalkString(schema, f));
        continue;
      }
      const size_t width = Width(f.kind);
      const size_t bytes = static_cast<size_t>(count) * width;
      if (bytes > remaining()) {
        return Status::Error(schema.name + "." + f.name + ": message truncated");
      }
      if (f.dims.empty()) values[i] = ReadInt(f.kind);
      pos_ += bytes;
    }
    return Status::Ok();
  }

  Status CheckHash(int64_t expected) {
    if (size_ < 8) return Status::Error("message shorter than its 8-byte type fingerprint");
    uint64_t h = 0;
    for (int i = 0; i < 8; ++i) h = (h << 8) | data_[i];
    pos_ = 8;
    if (static_cast<int64_t>(h) != expected) return Status::Error("wrong type fingerprint");
    return Status::Ok();
  }

  size_t remaining() const { return size_ - pos_; }

 private:
  static size_t Width(Kind k) {
    switch (k) {
      case Kind::kInt8: case Kind::kByte: case Kind::kBool: return 1;
      case Kind::kInt16: return 2;
      case Kind::kInt32: case Kind::kFloat: return 4;
      case Kind::kInt64: case Kind::kDouble: return 8;
      default: return 0;
    }
  }

  int64_t ReadInt(Kind k) const {
    uint64_t v = 0;
    const size_t w = Width(k);
    for (size_t b = 0; b < w; ++b) v = (v << 8) | data_[pos_ + b];
    switch (k) {
      case Kind::kInt8: return static_cast<int8_t>(v);
      case Kind::kInt16: return static_cast<int16_t>(v);
      case Kind::kInt32: return static_cast<int32_t>(v);
      case Kind::kInt64: return static_cast<int64_t>(v);
      case Kind::kByte: return static_cast<uint8_t>(v);
      default: return 0;
    }
  }

  Status WalkString(const Schema& schema, const Field& f) {
    if (remaining() < 4) return Status::Error(schema.name + "." + f.name + ": truncated string");
    const int64_t len = ReadInt(Kind::kInt32);  // includes the NUL
    pos_ += 4;
    if (len < 1 || static_cast<uint64_t>(len) > remaining()) {
      return Status::Error(schema.name + "." + f.name + ": bad string length " +
                           std::to_string(len));
    }
    if (data_[pos_ + static_cast<size_t>(len) - 1] != 0) {
      return Status::Error(schema.name + "." + f.name + ": string not NUL-terminated");
    }
    // LCM strings are C strings: lcm-gen's C++ decoder keeps bytes after an inner NUL,
    // but its encoder stops at the first one while getEncodedSize() counts them all,
    // so such a string re-published or logged leaves unwritten bytes in the message.
    if (len > 1 && std::memchr(data_ + pos_, 0, static_cast<size_t>(len) - 1) != nullptr) {
      return Status::Error(schema.name + "." + f.name + ": string with a NUL byte inside");
    }
    pos_ += static_cast<size_t>(len);
    return Status::Ok();
  }

  const uint8_t* data_;
  size_t size_;
  size_t pos_ = 0;
};

// Writes a random valid encoding of a schema.
class RandomEncoder {
 public:
  RandomEncoder(uint32_t seed, int max_array) : state_(seed * 2654435761u + 1u), max_array_(max_array) {}

  void Struct(const Schema& schema, int depth, std::vector<uint8_t>* out) {
    // Integer fields that size later arrays get small values.
    std::vector<bool> is_length(schema.fields.size(), false);
    for (const Field& f : schema.fields) {
      for (const Dim& d : f.dims) {
        if (d.length_field >= 0) is_length[static_cast<size_t>(d.length_field)] = true;
      }
    }
    std::vector<int64_t> values(schema.fields.size(), 0);
    for (size_t i = 0; i < schema.fields.size(); ++i) {
      const Field& f = schema.fields[i];
      int64_t count = 1;
      for (const Dim& d : f.dims) count *= d.length_field >= 0 ? values[static_cast<size_t>(d.length_field)] : d.fixed;
      for (int64_t k = 0; k < count; ++k) {
        if (f.kind == Kind::kStruct) {
          auto it = Schemas().find(f.struct_name);
          if (it != Schemas().end() && depth < 8) Struct(it->second, depth + 1, out);
        } else if (f.kind == Kind::kString) {
          const int len = static_cast<int>(Rand() % 12);
          PutBigEndian(static_cast<uint64_t>(len + 1), 4, out);
          for (int c = 0; c < len; ++c) out->push_back(static_cast<uint8_t>('a' + Rand() % 26));
          out->push_back(0);
        } else if (is_length[i] && f.dims.empty()) {
          values[i] = static_cast<int64_t>(Rand() % static_cast<uint32_t>(max_array_ + 1));
          PutBigEndian(static_cast<uint64_t>(values[i]), Width(f.kind), out);
        } else if (f.kind == Kind::kFloat) {
          const float v = static_cast<float>(static_cast<int32_t>(Rand())) / 65536.0f;
          uint32_t bits;
          std::memcpy(&bits, &v, 4);
          PutBigEndian(bits, 4, out);
        } else if (f.kind == Kind::kDouble) {
          const double v = static_cast<double>(static_cast<int32_t>(Rand())) / 1024.0;
          uint64_t bits;
          std::memcpy(&bits, &v, 8);
          PutBigEndian(bits, 8, out);
        } else if (f.kind == Kind::kBool) {
          out->push_back(static_cast<uint8_t>(Rand() & 1));
        } else {
          const uint64_t v = (static_cast<uint64_t>(Rand()) << 32) | Rand();
          PutBigEndian(v, Width(f.kind), out);
        }
      }
    }
  }

  static size_t Width(Kind k) {
    switch (k) {
      case Kind::kInt8: case Kind::kByte: case Kind::kBool: return 1;
      case Kind::kInt16: return 2;
      case Kind::kInt32: case Kind::kFloat: return 4;
      default: return 8;
    }
  }
  static void PutBigEndian(uint64_t v, size_t width, std::vector<uint8_t>* out) {
    for (size_t b = 0; b < width; ++b) out->push_back(static_cast<uint8_t>(v >> (8 * (width - 1 - b))));
  }

 private:
  uint32_t Rand() {  // xorshift32
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return state_;
  }
  uint32_t state_;
  int max_array_;
};

}  // namespace

std::vector<uint8_t> RandomLcmEncoding(const std::string& type_name, int64_t hash, uint32_t seed,
                                       int max_array) {
  std::vector<uint8_t> out;
  auto it = Schemas().find(type_name);
  if (it == Schemas().end()) return out;
  RandomEncoder::PutBigEndian(static_cast<uint64_t>(hash), 8, &out);
  RandomEncoder encoder(seed, max_array);
  encoder.Struct(it->second, 0, &out);
  return out;
}

Status CheckLcmEncoding(const std::string& type_name, int64_t expected_hash, const uint8_t* data,
                        size_t size) {
  auto it = Schemas().find(type_name);
  if (it == Schemas().end()) return Status::Error("no schema for type " + type_name);
  Walker walker(data, size);
  MBSLAM_RETURN_IF_ERROR(walker.CheckHash(expected_hash).WithContext(type_name));
  MBSLAM_RETURN_IF_ERROR(walker.WalkStruct(it->second, 0));
  if (walker.remaining() != 0) {
    return Status::Error(type_name + ": " + std::to_string(walker.remaining()) +
                         " trailing bytes after the message");
  }
  return Status::Ok();
}

std::string LcmSchemaTypeNames() {
  std::string out;
  for (const auto& kv : Schemas()) {
    if (!out.empty()) out += " ";
    out += kv.first;
  }
  return out;
}

}  // namespace mbslam
