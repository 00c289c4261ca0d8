#ifndef MBSLAM_VIEWER_SNAPSHOT_FILES_H_
#define MBSLAM_VIEWER_SNAPSHOT_FILES_H_

// Names and atomic writing of the PNG snapshots.

#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

#include "common/util/status.h"

namespace mbslam {
namespace viewer {

// "<prefix><view>_<utime, 16 digits>.png" (sorts by time), or "<prefix><view>_latest.png"
// when utime < 0.
std::string SnapshotPath(const std::string& prefix, const std::string& view, int64_t utime);

// PNG file bytes of a BGR image (fast zlib level: snapshots are written often).
Status EncodePng(const cv::Mat& bgr, std::string* png);

// Writes file bytes atomically (temporary file, fsync, rename), after creating the
// parent directory if needed.
Status WriteBytesAtomically(const std::string& path, const std::string& bytes);

// Makes `path` another name of the existing file `target` (hard link to a temporary
// name, renamed over `path`): the "latest" copy of a snapshot without writing it twice.
Status LinkAtomically(const std::string& target, const std::string& path);

// EncodePng + WriteBytesAtomically.
Status WritePngAtomically(const std::string& path, const cv::Mat& bgr);

// Where the files of a snapshot request go (ResolveRequestPath, common/util/
// request_path.h). An empty request prefix means "<output_dir>/". A relative prefix
// without ".." is placed under output_dir; an absolute one or one with ".." is honoured
// only when allow_any_path is set, else it is refused (Status error; the caller then
// uses "<output_dir>/"); control characters are always refused.
Status ResolveRequestPrefix(const std::string& output_dir, const std::string& request_prefix,
                            bool allow_any_path, std::string* prefix);

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_SNAPSHOT_FILES_H_
