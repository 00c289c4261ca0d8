#ifndef MBSLAM_SERVICES_PERCEPTION_PERCEPTION_SERVICE_H_
#define MBSLAM_SERVICES_PERCEPTION_PERCEPTION_SERVICE_H_

// The perception service as an object: owns the bus, the pipeline, the adapters and
// the outputs. perception_main.cc parses arguments and calls Run(); integration tests
// drive it on a memq:// bus shared with their own publishers.

#include <atomic>
#include <memory>
#include <string>

#include "common/lcm/lcm_bus.h"
#include "common/lcm/lcm_log.h"
#include "common/util/status.h"
#include "services/perception/lcm_adapters/input_adapter.h"
#include "services/perception/lcm_adapters/output_adapter.h"
#include "services/perception/perception_options.h"
#include "services/perception/pipeline/perception_core.h"
#include "services/perception/pipeline/pipeline.h"
#include "services/perception/pipeline/result_recorder.h"

namespace mbslam {

class PerceptionService {
 public:
  // `bus` may be given (shared memq:// bus in tests); otherwise one is opened from
  // options.service.lcm_url.
  static std::unique_ptr<PerceptionService> Create(const PerceptionOptions& options,
                                                   Status* status, LcmBus* bus = nullptr);
  ~PerceptionService();

  // Handles messages until Shutdown(), a signal (ShutdownRequested()), or the end of a
  // file:// log; then stops the pipeline, publishes a final status and writes outputs.
  Status Run();
  // Dispatches at most one message and publishes status when due. Returns false at
  // the end of a file:// log.
  bool RunOnce(int timeout_ms);
  // Stops the pipeline (lockstep: after processing everything received), publishes the
  // final status, writes the outputs. Idempotent.
  Status Finish();
  void Shutdown() { shutdown_ = true; }

  Status WriteOutputs(const std::string& dir);
  PipelineStatus last_status() const { return last_status_; }
  const Counters& counters() const { return counters_; }
  LcmBus* bus() { return bus_; }

 private:
  explicit PerceptionService(const PerceptionOptions& options);
  void MaybePublishStatus();

  const PerceptionOptions options_;
  std::unique_ptr<LcmBus> owned_bus_;
  LcmBus* bus_ = nullptr;
  std::unique_ptr<LcmLogWriter> output_log_;
  Counters counters_;
  StageTimers timers_;
  std::unique_ptr<PerceptionCore> core_;
  std::unique_ptr<LcmOutputSink> lcm_sink_;
  ResultRecorder recorder_;
  std::unique_ptr<TeeSink> sink_;
  std::unique_ptr<PerceptionPipeline> pipeline_;
  std::unique_ptr<InputAdapter> adapter_;
  bool from_log_ = false;
  bool started_ = false;   // Create() got to the end (its failures destroy a partial service)
  bool finished_ = false;
  std::atomic<bool> shutdown_{false};
  int64_t last_status_utime_ = 0;
  int64_t last_status_wall_ = 0;
  PipelineStatus last_status_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PERCEPTION_SERVICE_H_
