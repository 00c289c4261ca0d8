#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_STAGE_TIMERS_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_STAGE_TIMERS_H_

// Per-stage wall-time statistics, reported on PERCEPTION_STATUS.

#include <deque>
#include <mutex>
#include <string>
#include <vector>

#include "common/util/time.h"
#include "common/util/timing_stats.h"

namespace mbslam {

class StageTimers {
 public:
  // The stats of a stage, created on first use; stages are reported in creation order.
  TimingStats* Get(const std::string& name, double budget_ms = 0.0) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (TimingStats& s : stats_) {
      if (s.name() == name) return &s;
    }
    stats_.emplace_back(name, budget_ms);
    return &stats_.back();
  }
  std::vector<TimingStats*> All() {
    std::lock_guard<std::mutex> lock(mutex_);
    std::vector<TimingStats*> out;
    for (TimingStats& s : stats_) out.push_back(&s);
    return out;
  }

 private:
  std::mutex mutex_;
  std::deque<TimingStats> stats_;  // deque: stable addresses
};

// Adds the scope's wall time to a stage on destruction.
class ScopedStageTimer {
 public:
  explicit ScopedStageTimer(TimingStats* stats) : stats_(stats), start_(MonotonicUtime()) {}
  ~ScopedStageTimer() { stats_->Add(UtimeToMs(MonotonicUtime() - start_)); }
  ScopedStageTimer(const ScopedStageTimer&) = delete;
  ScopedStageTimer& operator=(const ScopedStageTimer&) = delete;

 private:
  TimingStats* stats_;
  int64_t start_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_STAGE_TIMERS_H_
