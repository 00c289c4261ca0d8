#include "viewer/snapshot_files.h"

#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

#include "common/util/atomic_file.h"
#include "common/util/request_path.h"

namespace mbslam {
namespace viewer {

std::string SnapshotPath(const std::string& prefix, const std::string& view, int64_t utime) {
  if (utime < 0) return prefix + view + "_latest.png";
  char stamp[32];
  std::snprintf(stamp, sizeof(stamp), "%016lld", static_cast<long long>(utime));
  return prefix + view + "_" + stamp + ".png";
}

Status EncodePng(const cv::Mat& bgr, std::string* png) {
  if (bgr.empty()) return Status::Error("empty image");
  std::vector<uint8_t> bytes;
  try {
    if (!cv::imencode(".png", bgr, bytes, {cv::IMWRITE_PNG_COMPRESSION, 1})) {
      return Status::Error("PNG encoding failed");
    }
  } catch (const cv::Exception& e) {
    return Status::Error(std::string("PNG encoding threw: ") + e.what());
  }
  png->assign(bytes.begin(), bytes.end());
  return Status::Ok();
}

Status WriteBytesAtomically(const std::string& path, const std::string& bytes) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(parent, ec);
    if (ec) return Status::Error("cannot create " + parent.string() + ": " + ec.message());
  }
  return WriteStringAtomically(path, bytes);
}

Status LinkAtomically(const std::string& target, const std::string& path) {
  const std::string tmp = path + ".tmp.link." + std::to_string(::getpid());
  std::remove(tmp.c_str());
  if (::link(target.c_str(), tmp.c_str()) != 0) {
    return Status::Error("cannot link " + tmp + " to " + target + ": " + std::strerror(errno));
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    const std::string error = std::strerror(errno);
    std::remove(tmp.c_str());
    return Status::Error("cannot rename " + tmp + " to " + path + ": " + error);
  }
  return Status::Ok();
}

Status WritePngAtomically(const std::string& path, const cv::Mat& bgr) {
  std::string png;
  MBSLAM_RETURN_IF_ERROR(EncodePng(bgr, &png).WithContext(path));
  return WriteBytesAtomically(path, png);
}

Status ResolveRequestPrefix(const std::string& output_dir, const std::string& request_prefix,
                            bool allow_any_path, std::string* prefix) {
  const Status s = ResolveRequestPath(output_dir, request_prefix, allow_any_path, prefix);
  if (!s.ok()) {
    return Status::Error("snapshot request path prefix: " + s.message() +
                         (allow_any_path ? "" : " (viewer.allow_request_paths is off)"));
  }
  return s;
}

}  // namespace viewer
}  // namespace mbslam
