#include "viewer/snapshot_files.h"

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <system_error>
#include <vector>

#include "common/util/atomic_file.h"

namespace mbslam {
namespace viewer {

std::string SnapshotPath(const std::string& prefix, const std::string& view, int64_t utime) {
  if (utime < 0) return prefix + view + "_latest.png";
  char stamp[32];
  std::snprintf(stamp, sizeof(stamp), "%016lld", static_cast<long long>(utime));
  return prefix + view + "_" + stamp + ".png";
}

Status WritePngAtomically(const std::string& path, const cv::Mat& bgr) {
  if (bgr.empty()) return Status::Error("empty image for " + path);
  std::vector<uint8_t> png;
  try {
    if (!cv::imencode(".png", bgr, png, {cv::IMWRITE_PNG_COMPRESSION, 3})) {
      return Status::Error("PNG encoding failed for " + path);
    }
  } catch (const cv::Exception& e) {
    return Status::Error("PNG encoding threw for " + path + ": " + e.what());
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    if (ec) return Status::Error("cannot create " + parent.string() + ": " + ec.message());
  }
  return WriteStringAtomically(path, std::string(png.begin(), png.end()));
}

Status ResolveRequestPrefix(const std::string& output_dir, const std::string& request_prefix,
                            bool allow_any_path, std::string* prefix) {
  const std::string base = output_dir.empty() ? std::string("./") : output_dir + "/";
  *prefix = base;
  if (request_prefix.empty()) return Status::Ok();
  const std::filesystem::path p(request_prefix);
  bool has_dot_dot = false;
  for (const auto& part : p) has_dot_dot = has_dot_dot || part == "..";
  if (p.is_absolute() || has_dot_dot) {
    if (!allow_any_path) {
      return Status::Error("snapshot request path prefix '" + request_prefix +
                           "' leaves the output directory (viewer.allow_request_paths is off)");
    }
    *prefix = request_prefix;
    return Status::Ok();
  }
  *prefix = base + request_prefix;
  return Status::Ok();
}

}  // namespace viewer
}  // namespace mbslam
