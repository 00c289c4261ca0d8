#ifndef MBSLAM_COMMON_UTIL_ATOMIC_FILE_H_
#define MBSLAM_COMMON_UTIL_ATOMIC_FILE_H_

#include <functional>
#include <ostream>
#include <string>

#include "common/util/status.h"

namespace mbslam {

// Writes a file atomically: `write` fills a temporary file next to `path`, which is
// flushed, fsync'ed and renamed over `path`. A crash at any point leaves either the
// old file or the new one, never a torn file.
Status WriteFileAtomically(const std::string& path,
                           const std::function<bool(std::ostream&)>& write);

Status WriteStringAtomically(const std::string& path, const std::string& contents);

// Removes the temporary files (`NAME.tmp.PID`) that writers killed mid-write left in
// `dir`: only those whose process no longer exists. Returns how many were removed.
int RemoveStaleTempFiles(const std::string& dir);

// Reads a whole file (bounded by max_bytes) into `contents`.
Status ReadFileToString(const std::string& path, std::string* contents,
                        size_t max_bytes = size_t{1} << 30);

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_ATOMIC_FILE_H_
