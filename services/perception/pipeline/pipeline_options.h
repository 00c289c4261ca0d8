#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_PIPELINE_OPTIONS_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_PIPELINE_OPTIONS_H_

#include <cstdint>
#include <string>

#include "common/config/options.h"

namespace mbslam {

struct PipelineOptions {
  std::string mode = "realtime";        // "realtime" (drop stale frames) or "lockstep" (every frame, deterministic)
  int image_queue_capacity = 1;         // realtime: images waiting for decode / processing; 1 = only the newest waits (count)
  int lockstep_queue_capacity = 16;     // lockstep: events buffered before the reader blocks (count)
  int aux_queue_capacity = 4096;        // realtime: odometry / calibration events buffered (count)
  int max_image_dimension = 8192;       // larger width or height is rejected (px)
  int64_t max_frame_gap_us = 1000000;   // a larger forward jump of image time is reported (µs)
  int64_t status_period_us = 1000000;   // PERCEPTION_STATUS period in message time (µs)
  int64_t stall_timeout_us = 2000000;   // no image for this long (wall) = STALLED (µs)
  // The C heap figures on PERCEPTION_STATUS come from glibc's mallinfo2, which walks the
  // allocator's free lists under its locks: 0.3-0.5 ms on sim-multi's heap, but it grows
  // with the free chunks (85 ms with 200,000 of them). Taken at most this often (wall µs;
  // 0 = never: the heap fields stay -1); the resident set is read at every status.
  int64_t heap_stats_period_us = 10000000;
  double frame_budget_ms = 33.3;        // per-frame processing budget; overruns are counted (ms)
  std::string timing_log;               // per-image timing CSV written here ("" = none)

  bool lockstep() const { return mode == "lockstep"; }

  bool Check() const {
    MBSLAM_CHECK_OPTION(mode == "realtime" || mode == "lockstep");
    MBSLAM_CHECK_OPTION_GT(image_queue_capacity, 0);
    MBSLAM_CHECK_OPTION_GT(lockstep_queue_capacity, 0);
    MBSLAM_CHECK_OPTION_GT(aux_queue_capacity, 0);
    MBSLAM_CHECK_OPTION_GT(max_image_dimension, 16);
    MBSLAM_CHECK_OPTION_GT(max_frame_gap_us, 0);
    MBSLAM_CHECK_OPTION_GT(status_period_us, 0);
    MBSLAM_CHECK_OPTION_GT(stall_timeout_us, 0);
    MBSLAM_CHECK_OPTION_GE(heap_stats_period_us, 0);
    MBSLAM_CHECK_OPTION_GT(frame_budget_ms, 0.0);
    return true;
  }

  template <typename V>
  void VisitFields(V& v) {
    v("mode", &mode, "realtime (drop stale frames, count them) | lockstep (every frame, deterministic)");
    v("image_queue_capacity", &image_queue_capacity, "realtime image queue length (count)");
    v("lockstep_queue_capacity", &lockstep_queue_capacity, "lockstep event queue length (count)");
    v("aux_queue_capacity", &aux_queue_capacity, "realtime odometry/calibration queue length (count)");
    v("max_image_dimension", &max_image_dimension, "largest accepted width or height (px)");
    v("max_frame_gap_us", &max_frame_gap_us, "forward time jump reported as a gap (us)");
    v("status_period_us", &status_period_us, "PERCEPTION_STATUS period in message time (us)");
    v("stall_timeout_us", &stall_timeout_us, "no image for this long (wall) means STALLED (us)");
    v("heap_stats_period_us", &heap_stats_period_us,
      "C heap figures on PERCEPTION_STATUS (mallinfo2, holds the allocator's locks) at most this often (wall us; 0 = never)");
    v("frame_budget_ms", &frame_budget_ms, "per-frame processing budget (ms)");
    v("timing_log", &timing_log,
      "per-image timing CSV: seq, utime, queue wait, each stage's time in that image, latency (\"\" = none)");
  }
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_PIPELINE_OPTIONS_H_
