#ifndef MBSLAM_TOOLS_EVAL_JSON_H_
#define MBSLAM_TOOLS_EVAL_JSON_H_

// A small JSON value for evaluation reports: objects keep their insertion order, numbers
// are doubles or int64, non-finite doubles are written as null.
//
//   Json j = Json::Object();
//   j.Set("ate_rmse_m", 0.012).Set("frames", int64_t{300});
//   std::cout << j.Dump() << "\n";

#include <cstdint>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace mbslam {
namespace eval {

class Json {
 public:
  enum class Type { kNull, kBool, kInt, kDouble, kString, kArray, kObject };

  Json() = default;                                                     // null
  Json(bool v) : type_(Type::kBool), bool_(v) {}                        // NOLINT(runtime/explicit)
  Json(int v) : type_(Type::kInt), int_(v) {}                           // NOLINT(runtime/explicit)
  Json(int64_t v) : type_(Type::kInt), int_(v) {}                       // NOLINT(runtime/explicit)
  Json(size_t v) : type_(Type::kInt), int_(static_cast<int64_t>(v)) {}  // NOLINT(runtime/explicit)
  Json(double v) : type_(Type::kDouble), double_(v) {}                  // NOLINT(runtime/explicit)
  Json(const char* v) : type_(Type::kString), string_(v) {}             // NOLINT(runtime/explicit)
  Json(std::string v) : type_(Type::kString), string_(std::move(v)) {}  // NOLINT(runtime/explicit)
  Json(const std::vector<double>& values);                              // NOLINT(runtime/explicit)

  static Json Object() {
    Json j;
    j.type_ = Type::kObject;
    return j;
  }
  static Json Array() {
    Json j;
    j.type_ = Type::kArray;
    return j;
  }

  Type type() const { return type_; }
  // Object: sets (or replaces) a key. Turns a null value into an object.
  Json& Set(const std::string& key, Json value);
  // Array: appends. Turns a null value into an array.
  Json& Push(Json value);

  // Object lookup (nullptr if absent or not an object).
  const Json* Find(const std::string& key) const;
  double AsDouble() const;  // numbers (NaN for others)
  const std::string& AsString() const { return string_; }
  size_t size() const { return type_ == Type::kArray ? array_.size() : members_.size(); }
  const Json& operator[](size_t i) const { return array_[i]; }

  // Compact single-line text.
  std::string Dump() const;

  // Parses JSON text (numbers, strings with simple escapes, arrays, objects, literals).
  static bool Parse(const std::string& text, Json* out, std::string* error = nullptr);

 private:
  void DumpTo(std::string* out) const;

  Type type_ = Type::kNull;
  bool bool_ = false;
  int64_t int_ = 0;
  double double_ = 0.0;
  std::string string_;
  std::vector<Json> array_;
  std::vector<std::pair<std::string, Json>> members_;
};

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_JSON_H_
