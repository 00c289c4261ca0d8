#include "drivers/camera/frame_source.h"

#include "drivers/common/exit_codes.h"

namespace mbslam {

const char* SourceErrorName(SourceError error) {
  switch (error) {
    case SourceError::kNone: return "ok";
    case SourceError::kConfig: return "configuration error";
    case SourceError::kNotFound: return "input not found";
    case SourceError::kNoCamera: return "no camera";
    case SourceError::kBadMode: return "unsupported camera mode";
    case SourceError::kDisconnected: return "camera lost";
    case SourceError::kAccess: return "camera not accessible";
    case SourceError::kIo: return "read error";
    case SourceError::kOutput: return "output error";
  }
  return "unknown";
}

int ExitCodeFor(SourceError error) {
  switch (error) {
    case SourceError::kNone: return kExitOk;
    case SourceError::kConfig: return kExitUsage;
    case SourceError::kNotFound: return kExitInputNotFound;
    case SourceError::kNoCamera: return kExitNoCamera;
    case SourceError::kBadMode: return kExitBadMode;
    case SourceError::kDisconnected: return kExitCameraLost;
    case SourceError::kAccess: return kExitCameraAccess;
    case SourceError::kIo: return kExitBadData;
    case SourceError::kOutput: return kExitOutputError;
  }
  return kExitRuntimeError;
}

}  // namespace mbslam
