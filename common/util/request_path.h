#ifndef MBSLAM_COMMON_UTIL_REQUEST_PATH_H_
#define MBSLAM_COMMON_UTIL_REQUEST_PATH_H_

// Where files named by a remote request may go. LCM has no authentication, so a path
// in a message (snapshot_request_t.path_prefix) must not choose an arbitrary place in
// the file system.

#include <string>

#include "common/util/status.h"

namespace mbslam {

// An empty request gives "<base_dir>/" ("./" when base_dir is empty). A relative
// request without ".." components is placed under base_dir ("<base_dir>/<request>");
// an absolute one or one with ".." is honoured as it is only when allow_any_path is
// set, else refused. Control characters (NUL included: the file system would cut the
// name there) are always refused. On error `*resolved` is "<base_dir>/".
Status ResolveRequestPath(const std::string& base_dir, const std::string& request,
                          bool allow_any_path, std::string* resolved);

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_REQUEST_PATH_H_
