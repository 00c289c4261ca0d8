#ifndef MBSLAM_VIEWER_LCM_ADAPTER_H_
#define MBSLAM_VIEWER_LCM_ADAPTER_H_

// The only viewer code that sees LCM: subscribes to the perception outputs, the camera
// images and snapshot requests, decodes every message with the bounds-checked
// DecodeLcmMessage, converts it into the plain structs of scene.h and hands it to a
// SceneState. Bad messages (truncated, corrupted, wrong type, non-finite poses) are
// counted per channel and dropped; nothing here throws.

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/map_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "mbslam/snapshot_request_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "viewer/scene.h"

namespace mbslam {
namespace viewer {

// Conversions. Each returns an error for content the viewer cannot use (a non-finite
// camera pose, a hull whose arrays disagree, an unknown image encoding).
Status FromLcm(const mbslam::camera_pose_t& m, CameraPoseSample* out);
Status FromLcm(const mbslam::map_t& m, MapData* out);
Status FromLcm(const mbslam::objects_t& m, ObjectsData* out);
Status FromLcm(const mbslam::occupancy_t& m, EncodedOccupancy* out);
Status FromLcm(const mbslam::tracks_t& m, TracksData* out);
Status FromLcm(mbslam::image_t&& m, EncodedImage* out);

struct ChannelCounts {
  int64_t received = 0;    // messages seen (count)
  int64_t bad = 0;         // messages dropped as undecodable or invalid (count)
  std::string last_error;  // reason of the last bad one
};

class ViewerLcmAdapter {
 public:
  // Called before a message with this utime (µs) is applied to the scene: the periodic
  // snapshot schedule runs on message time.
  using MessageTimeHook = std::function<void(int64_t utime)>;
  // A snapshot request: bit set of snapshot_request_t.WHAT_*, the path prefix.
  using SnapshotHook = std::function<void(int what, const std::string& path_prefix)>;

  // Subscribes on `bus` (which must outlive the adapter); `scene` receives the data.
  ViewerLcmAdapter(LcmBus* bus, const ChannelOptions& channels, int queue_capacity,
                   size_t max_message_bytes, SceneState* scene);

  void SetMessageTimeHook(MessageTimeHook hook) { time_hook_ = std::move(hook); }
  void SetSnapshotHook(SnapshotHook hook) { snapshot_hook_ = std::move(hook); }

  // Per channel name.
  const std::map<std::string, ChannelCounts>& counts() const { return counts_; }
  int64_t bad_total() const;
  int64_t received_total() const;

 private:
  template <typename Msg>
  bool Decode(const std::string& channel, const uint8_t* data, size_t size, Msg* msg);
  void Bad(const std::string& channel, const std::string& why);
  void BeforeMessage(int64_t utime);

  SceneState* scene_;
  size_t max_message_bytes_;
  std::map<std::string, ChannelCounts> counts_;
  MessageTimeHook time_hook_;
  SnapshotHook snapshot_hook_;
};

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_LCM_ADAPTER_H_
