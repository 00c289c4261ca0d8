#ifndef MBSLAM_COMMON_CONFIG_OPTIONS_YAML_H_
#define MBSLAM_COMMON_CONFIG_OPTIONS_YAML_H_

// Reading options structs (see options.h) from YAML and writing them back out.

#include <yaml-cpp/yaml.h>

#include <array>
#include <cstdint>
#include <set>
#include <string>
#include <vector>

#include "common/config/options.h"
#include "common/util/status.h"

namespace mbslam {
namespace internal {

template <typename T>
struct IsDoubleArray : std::false_type {};
template <size_t N>
struct IsDoubleArray<std::array<double, N>> : std::true_type {};

Status ParseScalar(const YAML::Node& node, const std::string& path, bool* value);
Status ParseScalar(const YAML::Node& node, const std::string& path, int* value);
Status ParseScalar(const YAML::Node& node, const std::string& path, int64_t* value);
Status ParseScalar(const YAML::Node& node, const std::string& path, double* value);
Status ParseScalar(const YAML::Node& node, const std::string& path, float* value);
Status ParseScalar(const YAML::Node& node, const std::string& path, std::string* value);
Status ParseScalar(const YAML::Node& node, const std::string& path, std::vector<double>* value);
Status ParseScalar(const YAML::Node& node, const std::string& path,
                   std::vector<std::string>* value);
Status ParseDoubleArray(const YAML::Node& node, const std::string& path, double* values,
                        size_t count);

std::string FormatScalar(bool value);
std::string FormatScalar(int value);
std::string FormatScalar(int64_t value);
std::string FormatScalar(double value);
std::string FormatScalar(float value);
std::string FormatScalar(const std::string& value);
std::string FormatScalar(const std::vector<double>& value);
std::string FormatScalar(const std::vector<std::string>& value);
std::string FormatDoubleArray(const double* values, size_t count);

std::string JoinPath(const std::string& prefix, const char* name);
std::string Sorted(const std::set<std::string>& names);

class YamlReader {
 public:
  YamlReader(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {}

  template <typename T>
  void operator()(const char* name, T* field, const char* /*comment*/) {
    known_.insert(name);
    if (!status_.ok()) return;
    const YAML::Node child = node_[name];
    if (!child.IsDefined() || child.IsNull()) return;  // keep the default
    const std::string path = JoinPath(path_, name);
    if constexpr (kIsOptionsStruct<T>) {
      status_ = ReadSection(child, path, field);
    } else if constexpr (IsDoubleArray<T>::value) {
      status_ = ParseDoubleArray(child, path, field->data(), field->size());
    } else {
      status_ = ParseScalar(child, path, field);
    }
  }

  // Checks that every key of the node was a known field.
  Status Finish() const {
    if (!status_.ok()) return status_;
    for (const auto& kv : node_) {
      // A key that is a list or a mapping ("? [a, b]: 1"): as<std::string>() threw
      // YAML::BadConversion out of the loader (found by fuzz_config_yaml).
      if (!kv.first.IsScalar()) {
        return Status::Error("option section '" + (path_.empty() ? std::string("<root>") : path_) +
                             "' has a key that is not a name");
      }
      const std::string key = kv.first.Scalar();
      if (!known_.count(key)) {
        return Status::Error("unknown option '" + JoinPath(path_, key.c_str()) +
                             "' (known here: " + Sorted(known_) + ")");
      }
    }
    return Status::Ok();
  }

  template <typename T>
  static Status ReadSection(const YAML::Node& node, const std::string& path, T* options) {
    if (!node.IsMap()) {
      return Status::Error("option section '" + (path.empty() ? std::string("<root>") : path) +
                           "' must be a mapping");
    }
    YamlReader reader(node, path);
    options->VisitFields(reader);
    return reader.Finish();
  }

 private:
  const YAML::Node node_;
  const std::string path_;
  std::set<std::string> known_;
  Status status_;
};

class YamlWriter {
 public:
  explicit YamlWriter(int indent) : indent_(indent) {}

  template <typename T>
  void operator()(const char* name, T* field, const char* comment) {
    const std::string pad(static_cast<size_t>(indent_), ' ');
    if constexpr (kIsOptionsStruct<T>) {
      out_ += pad + name + ":";
      if (comment && *comment) out_ += "  # " + std::string(comment);
      out_ += "\n";
      YamlWriter nested(indent_ + 2);
      field->VisitFields(nested);
      out_ += nested.out_;
    } else if constexpr (IsDoubleArray<T>::value) {
      Line(pad, name, FormatDoubleArray(field->data(), field->size()), comment);
    } else {
      Line(pad, name, FormatScalar(*field), comment);
    }
  }
  const std::string& text() const { return out_; }

 private:
  void Line(const std::string& pad, const char* name, const std::string& value,
            const char* comment) {
    out_ += pad + name + ": " + value;
    if (comment && *comment) out_ += "  # " + std::string(comment);
    out_ += "\n";
  }
  int indent_;
  std::string out_;
};

}  // namespace internal

// YAML text must be UTF-8 (YAML 1.2). yaml-cpp loads other bytes as they are but its
// emitter writes them back as U+FFFD, so a file that loaded would not read back the
// same from --print-config / CameraIntrinsicsToYaml. `what` names the text in the
// error ("calibration", a file name).
Status CheckYamlTextIsUtf8(const std::string& text, const std::string& what);

// Fills `options` from a YAML mapping; missing keys keep their defaults. Fails on
// unknown keys, values of the wrong type, non-finite numbers, and a failed Check().
// On failure `options` is left unchanged.
template <typename T>
Status LoadOptionsFromYaml(const YAML::Node& node, const std::string& section, T* options) {
  T loaded = *options;
  try {
    MBSLAM_RETURN_IF_ERROR(internal::YamlReader::ReadSection(node, section, &loaded));
  } catch (const YAML::Exception& e) {  // the loader must never throw at its caller
    return Status::Error("YAML: " + std::string(e.what()));
  }
  if (!loaded.Check()) {
    return Status::Error((section.empty() ? std::string("options") : section) +
                         ": " + LastOptionError());
  }
  *options = std::move(loaded);
  return Status::Ok();
}

// Parses YAML text (not a file name) into options.
template <typename T>
Status LoadOptionsFromYamlText(const std::string& text, const std::string& section, T* options) {
  MBSLAM_RETURN_IF_ERROR(CheckYamlTextIsUtf8(text, "options"));
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    return Status::Error("YAML syntax error: " + std::string(e.what()));
  }
  if (root.IsNull()) {  // an empty document keeps every default
    if (!options->Check()) return Status::Error(LastOptionError());
    return Status::Ok();
  }
  return LoadOptionsFromYaml(root, section, options);
}

Status ReadYamlFile(const std::string& path, YAML::Node* root);

template <typename T>
Status LoadOptionsFromFile(const std::string& path, T* options) {
  YAML::Node root;
  MBSLAM_RETURN_IF_ERROR(ReadYamlFile(path, &root));
  if (root.IsNull()) {
    if (!options->Check()) return Status::Error(path + ": " + LastOptionError());
    return Status::Ok();
  }
  return LoadOptionsFromYaml(root, "", options).WithContext(path);
}

// The effective options as YAML with a comment per field (what a service prints at
// start, and the format of config/*.yaml).
template <typename T>
std::string OptionsToYaml(const T& options) {
  T copy = options;
  internal::YamlWriter writer(0);
  copy.VisitFields(writer);
  return writer.text();
}

}  // namespace mbslam

#endif  // MBSLAM_COMMON_CONFIG_OPTIONS_YAML_H_
