// Fuzz target: the options loader of every process (common/config/options_yaml.h) on
// YAML text, as `--config FILE` and `--set key=value` feed it. Input: one tag byte
// choosing the options struct (0 perception_service, 1 viewer, 2 camera_driver,
// 3 odometry_bridge; the driver structs only when drivers/ is built), then the text.
//
// Properties: nothing throws or crashes; options that load pass Check() and survive a
// round trip through OptionsToYaml (what --print-config writes reads back the same).

#include <string>

#include "common/config/options_yaml.h"
#include "services/perception/perception_options.h"
#include "test/fuzz/fuzz_util.h"
#include "viewer/viewer_options.h"
#ifdef MBSLAM_FUZZ_WITH_DRIVERS
#include "drivers/camera/camera_driver_options.h"
#include "drivers/odometry_bridge/odometry_bridge_options.h"
#endif

namespace {

template <typename Options>
void Load(const std::string& text) {
  Options options;
  if (!mbslam::LoadOptionsFromYamlText(text, "", &options).ok()) return;
  if (!options.Check()) mbslam::fuzz::Fail("loaded options fail Check()");
  const std::string printed = mbslam::OptionsToYaml(options);
  Options again;
  if (!mbslam::LoadOptionsFromYamlText(printed, "", &again).ok()) {
    mbslam::fuzz::Fail("OptionsToYaml output does not load");
  }
  if (mbslam::OptionsToYaml(again) != printed) {
    mbslam::fuzz::Fail("options change in a round trip through YAML");
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  if (size < 1) return 0;
  const std::string text(reinterpret_cast<const char*>(data + 1), size - 1);
  switch (data[0] % 4) {
    case 0: Load<mbslam::PerceptionOptions>(text); break;
    case 1: Load<mbslam::viewer::ViewerOptions>(text); break;
#ifdef MBSLAM_FUZZ_WITH_DRIVERS
    case 2: Load<mbslam::CameraDriverOptions>(text); break;
    case 3: Load<mbslam::OdometryBridgeOptions>(text); break;
#endif
    default: break;
  }
  return 0;
}
