#include "common/util/request_path.h"

#include <filesystem>

namespace mbslam {

Status ResolveRequestPath(const std::string& base_dir, const std::string& request,
                          bool allow_any_path, std::string* resolved) {
  const std::string base = base_dir.empty() ? std::string("./") : base_dir + "/";
  *resolved = base;
  if (request.empty()) return Status::Ok();
  for (char c : request) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      return Status::Error("requested path contains a control character");
    }
  }
  const std::filesystem::path p(request);
  bool has_dot_dot = false;
  for (const auto& part : p) has_dot_dot = has_dot_dot || part == "..";
  if (p.is_absolute() || has_dot_dot) {
    if (!allow_any_path) {
      return Status::Error("requested path '" + request + "' leaves " +
                           (base_dir.empty() ? std::string("the working directory") : base_dir));
    }
    *resolved = request;
    return Status::Ok();
  }
  *resolved = base + request;
  return Status::Ok();
}

}  // namespace mbslam
