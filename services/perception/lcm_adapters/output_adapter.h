#ifndef MBSLAM_SERVICES_PERCEPTION_LCM_ADAPTERS_OUTPUT_ADAPTER_H_
#define MBSLAM_SERVICES_PERCEPTION_LCM_ADAPTERS_OUTPUT_ADAPTER_H_

// FrameResult / PipelineStatus -> PERCEPTION_* messages, published on the bus and,
// when asked, written to an output log stamped with message time (byte-identical
// across lockstep replays of the same input).

#include <memory>
#include <mutex>

#include "common/lcm/channels.h"
#include "common/lcm/lcm_bus.h"
#include "common/lcm/lcm_log.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/map_t.hpp"
#include "mbslam/objects_t.hpp"
#include "mbslam/occupancy_t.hpp"
#include "mbslam/status_t.hpp"
#include "mbslam/tracks_t.hpp"
#include "services/perception/pipeline/outputs.h"
#include "services/perception/pipeline/pipeline.h"

namespace mbslam {

mbslam::camera_pose_t ToLcm(const CameraPoseOutput& pose);
mbslam::tracks_t ToLcmTracks(const FrameResult& result);
mbslam::objects_t ToLcmObjects(const FrameResult& result);
mbslam::map_t ToLcm(const MapOutput& map);
mbslam::occupancy_t ToLcm(const OccupancyOutput& occupancy);
mbslam::status_t ToLcm(const PipelineStatus& status);

class LcmOutputSink : public OutputSink {
 public:
  // `bus` may be null (log only); `log` may be null (bus only). `publish_tracks`
  // switches the debug PERCEPTION_TRACKS channel.
  LcmOutputSink(LcmBus* bus, LcmLogWriter* log, const ChannelOptions& channels,
                bool publish_tracks);

  void OnFrameResult(const FrameResult& result) override;
  // Status goes on the bus only: it carries wall-clock timings and would make the
  // output log differ between otherwise identical replays.
  void PublishStatus(const PipelineStatus& status);

 private:
  template <typename Msg>
  void Emit(const std::string& channel, int64_t utime, const Msg& msg);

  LcmBus* bus_;
  LcmLogWriter* log_;
  const ChannelOptions channels_;
  const bool publish_tracks_;
  std::mutex log_mutex_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_LCM_ADAPTERS_OUTPUT_ADAPTER_H_
