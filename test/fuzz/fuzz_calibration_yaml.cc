// Fuzz target: the camera calibration reader (ParseCameraIntrinsicsYaml, what
// --calibration / input.calibration_file load). Input: the YAML text.
//
// Properties: nothing throws or crashes; a calibration that loads is finite with
// positive focal lengths and a plausible size, and reads back from
// CameraIntrinsicsToYaml unchanged.

#include <cmath>
#include <string>

#include "services/perception/geometry/camera.h"
#include "test/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  const std::string text(reinterpret_cast<const char*>(data), size);
  mbslam::CameraIntrinsics c;
  if (!mbslam::ParseCameraIntrinsicsYaml(text, &c).ok()) return 0;
  if (!(std::isfinite(c.fx) && std::isfinite(c.fy) && c.fx > 0.0 && c.fy > 0.0 &&
        std::isfinite(c.cx) && std::isfinite(c.cy) && c.width > 0 && c.height > 0)) {
    mbslam::fuzz::Fail("accepted calibration is not finite / positive");
  }
  for (double d : c.distortion) {
    if (!std::isfinite(d)) mbslam::fuzz::Fail("accepted calibration has a non-finite coefficient");
  }
  mbslam::CameraIntrinsics again;
  if (!mbslam::ParseCameraIntrinsicsYaml(mbslam::CameraIntrinsicsToYaml(c), &again).ok()) {
    mbslam::fuzz::Fail("CameraIntrinsicsToYaml output does not load");
  }
  if (again.name != c.name || again.width != c.width || again.height != c.height ||
      again.fx != c.fx || again.fy != c.fy || again.cx != c.cx || again.cy != c.cy ||
      again.model != c.model || again.distortion != c.distortion) {
    mbslam::fuzz::Fail("calibration changes in a round trip through YAML");
  }
  return 0;
}
