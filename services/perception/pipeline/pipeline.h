#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_PIPELINE_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_PIPELINE_H_

// The threads of the perception service and their queues:
//
//   Push() (LCM thread) --> [input queue] --> decode thread --> [frame queue]
//                                                                  --> processing thread
//                                                                      FrameProcessor -> OutputSink
// realtime: image queues drop their oldest frame when full (counted as stale drops);
//           odometry bypasses them through its own queue, drained before each frame.
// lockstep: every event flows in arrival order through blocking queues; nothing is
//           dropped and the processor sees the same sequence on every replay.

#include <atomic>
#include <cstdint>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "common/util/bounded_queue.h"
#include "common/util/process_memory.h"
#include "common/util/timing_stats.h"
#include "services/perception/pipeline/counters.h"
#include "services/perception/pipeline/frame_processor.h"
#include "services/perception/pipeline/outputs.h"
#include "services/perception/pipeline/payloads.h"
#include "services/perception/pipeline/pipeline_options.h"
#include "services/perception/pipeline/stage_timers.h"

namespace mbslam {

enum class ServiceState { kStarting = 0, kRunning = 1, kDegraded = 2, kStalled = 3, kStopping = 4 };

struct QueueStatus {
  std::string name;
  int depth = 0;
  int capacity = 0;
  int64_t dropped = 0;
};

struct StageStatus {
  std::string name;
  TimingSummary timing;
};

struct PipelineStatus {
  int64_t utime = 0;           // latest input message time (µs)
  int64_t wall_utime = 0;      // when built (µs)
  ServiceState state = ServiceState::kStarting;
  std::string message;
  bool lockstep = false;
  int64_t frames_received = 0;
  int64_t frames_processed = 0;
  int64_t frames_dropped = 0;
  int64_t frames_rejected = 0;
  double input_fps = 0.0;      // message time
  double processed_fps = 0.0;  // wall time
  double latency_p50_ms = 0.0;
  double latency_p99_ms = 0.0;
  ProcessMemory memory;        // sampled when built
  int64_t results_kept_bytes = -1;  // what the output files' recorder holds (set by the service; -1 unknown)
  std::vector<StageStatus> stages;
  std::vector<QueueStatus> queues;
  std::vector<std::pair<std::string, int64_t>> counters;
};

class PerceptionPipeline {
 public:
  // `processor`, `sink`, `counters` and `timers` must outlive the pipeline.
  PerceptionPipeline(const PipelineOptions& options, FrameProcessor* processor, OutputSink* sink,
                     Counters* counters, StageTimers* timers);
  ~PerceptionPipeline();
  PerceptionPipeline(const PerceptionPipeline&) = delete;
  PerceptionPipeline& operator=(const PerceptionPipeline&) = delete;

  void Start();
  // Lockstep: processes everything pushed so far, then stops. Realtime: stops after
  // the frame in progress; queued frames are counted as dropped. Idempotent.
  void Stop();

  // Hands over an input event (images already validated by the adapter). In lockstep
  // mode this blocks while the pipeline is behind.
  void Push(InputEvent event);

  // Counts an image that the adapter rejected.
  void CountRejected() { ++frames_rejected_; }

  // Builds the status for the period since the previous call (drains stage timings).
  PipelineStatus BuildStatus(int64_t wall_utime);
  // Stage and latency timings over the whole run (for summaries and benchmarks).
  std::vector<StageStatus> RunTimings() const;

  int64_t frames_processed() const { return frames_processed_.load(); }
  int64_t frames_received() const { return frames_received_.load(); }
  int64_t last_image_wall_utime() const { return last_image_wall_utime_.load(); }
  bool lockstep() const { return options_.lockstep(); }

 private:
  using FrameEvent = std::variant<ImageFrame, OdometrySample>;

  void DecodeLoop();
  void ProcessLoop();
  void DrainOdometry();
  void ProcessImage(const ImageFrame& frame);
  // One line of the timing log (options_.timing_log) for the image just processed.
  void WriteTimingLine(const ImageFrame& frame, int64_t start_wall_utime, int64_t end_wall_utime);
  // Counts the camera tracking state leaving / regaining OK (processing thread).
  void CountTrackingTransition(TrackingState state);

  const PipelineOptions options_;
  FrameProcessor* processor_;
  OutputSink* sink_;
  Counters* counters_;
  StageTimers* timers_;
  TimingStats* decode_timer_;
  TimingStats* publish_timer_;  // the sink (encoding, publishing, recording) per image
  TimingStats* frame_timer_;
  TimingStats latency_;
  // Timing log (processing thread): the stages' columns are fixed at the first image.
  std::ofstream timing_log_;
  std::vector<TimingStats*> timing_log_stages_;
  std::vector<int64_t> timing_log_counts_;

  BoundedQueue<InputEvent> input_queue_;
  BoundedQueue<FrameEvent> frame_queue_;
  BoundedQueue<OdometrySample> odometry_queue_;  // realtime only

  std::thread decode_thread_;
  std::thread process_thread_;
  bool started_ = false;
  bool stopped_ = false;

  std::atomic<int64_t> frames_received_{0};
  std::atomic<int64_t> frames_processed_{0};
  std::atomic<int64_t> frames_rejected_{0};
  std::atomic<int64_t> latest_utime_{0};
  std::atomic<int64_t> last_image_wall_utime_{0};
  std::atomic<int> tracking_state_{static_cast<int>(TrackingState::kNotInitialized)};
  bool was_tracked_ = false;   // processing thread only
  bool ever_tracked_ = false;  // processing thread only

  // Period bookkeeping for rates (BuildStatus caller's thread only).
  int64_t period_start_wall_ = 0;
  ProcessMemory memory_;          // the latest figures for PERCEPTION_STATUS
  int64_t heap_sampled_wall_ = 0;  // when the heap figures were taken (wall µs; 0 = never)
  int64_t period_start_processed_ = 0;
  int64_t period_start_received_ = 0;
  int64_t period_first_utime_ = 0;
  std::vector<std::pair<std::string, int64_t>> previous_counters_;
};

const char* ServiceStateName(ServiceState state);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_PIPELINE_H_
