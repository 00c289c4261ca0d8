// Fuzz target: the viewer's LCM side (viewer/lcm_adapter.h) on memq://, then what the
// viewer does with the scene: the occupancy tree and the camera image decoded, the
// image view drawn. Input: records (fuzz_util.h), each one message; tag % 7 picks the
// channel: 0 PERCEPTION_CAMERA_POSE, 1 PERCEPTION_MAP, 2 PERCEPTION_OBJECTS,
// 3 PERCEPTION_OCCUPANCY, 4 PERCEPTION_TRACKS, 5 CAMERA_IMAGE, 6 SNAPSHOT_REQUEST.
//
// Properties: nothing throws or crashes; every message is counted as received, and
// the scene keeps only finite camera poses.

#include <string>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "test/fuzz/fuzz_util.h"
#include "viewer/image_view.h"
#include "viewer/lcm_adapter.h"
#include "viewer/render_options.h"
#include "viewer/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool quiet = (mbslam::fuzz::QuietLogs(), true);
  (void)quiet;
  using namespace mbslam;  // NOLINT: a fuzz target's body
  // One bus and adapter for the process (an LCM instance per execution left lazily
  // allocated LCM / glib state behind, so every execution ran a full leak scan); the
  // scene the adapter fills is reset for each input.
  static const ChannelOptions channels;
  static const std::string names[7] = {
      channels.perception_camera_pose, channels.perception_map,   channels.perception_objects,
      channels.perception_occupancy,   channels.perception_tracks, channels.camera_image,
      channels.snapshot_request};
  static viewer::SceneState scene;
  static std::unique_ptr<LcmBus> bus = [] {
    Status status;
    std::unique_ptr<LcmBus> b = LcmBus::Create("memq://", &status);
    if (!b) fuzz::Fail("memq:// bus");
    return b;
  }();
  static viewer::ViewerLcmAdapter adapter(bus.get(), channels, /*queue_capacity=*/16,
                                          /*max_message_bytes=*/size_t{64} << 20, &scene);
  scene = viewer::SceneState();
  const int64_t received_before = adapter.received_total();
  int64_t published = 0;
  for (const fuzz::Record& r : fuzz::SplitRecords(data, size, 12)) {
    bus->PublishRaw(names[r.tag % 7], r.data, static_cast<unsigned>(r.size));
    ++published;
    while (bus->HandleTimeout(0) > 0) {
    }
  }
  if (adapter.received_total() - received_before != published) fuzz::Fail("a published message was not counted");
  for (const viewer::CameraPoseSample& p : scene.camera_trajectory()) {
    if (!p.world_from_cam.position.allFinite()) fuzz::Fail("non-finite camera pose in the scene");
  }
  (void)scene.occupancy();
  // Drawn at a quarter of the camera size (min_width still applies): the drawing code is
  // the same, and an 8192 x 8192 canvas per execution would leave little time to fuzz.
  viewer::ImageViewOptions view_options;
  view_options.scale = 0.25;
  viewer::ImageViewInput input;
  (void)viewer::MakeImageViewInput(scene, viewer::SceneOptions().max_image_dimension, &input);
  cv::Mat bgr;
  viewer::RenderImageView(view_options, input, &bgr);
  return 0;
}
