#ifndef MBSLAM_COMMON_UTIL_TIMING_STATS_H_
#define MBSLAM_COMMON_UTIL_TIMING_STATS_H_

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

namespace mbslam {

// Summary of durations collected over one reporting period.
struct TimingSummary {
  int64_t count = 0;      // samples in the period
  double mean_ms = 0.0;   // ms
  double p50_ms = 0.0;    // ms
  double p99_ms = 0.0;    // ms
  double max_ms = 0.0;    // ms
  int64_t overruns = 0;   // samples above the budget
};

// Percentile (0..100) of a sample set by linear interpolation between order
// statistics; 0 for an empty set. Sorts `values`.
double Percentile(std::vector<double>* values, double percent);

// Collects durations of one stage; Drain() summarises and resets the period.
// Thread-safe. Keeps at most max_samples per period (a reservoir of the latest).
class TimingStats {
 public:
  explicit TimingStats(std::string name, double budget_ms = 0.0, size_t max_samples = 4096);

  void Add(double duration_ms);
  TimingSummary Drain();
  // Summary since construction (a bounded, evenly thinned sample of all durations).
  TimingSummary Cumulative() const;
  // Totals since construction (not reset by Drain).
  int64_t total_count() const;
  // The latest duration added (ms); 0 before the first.
  double last_ms() const;
  const std::string& name() const { return name_; }
  double budget_ms() const { return budget_ms_; }

 private:
  const std::string name_;
  const double budget_ms_;
  const size_t max_samples_;
  mutable std::mutex mutex_;
  std::vector<double> samples_;
  size_t next_ = 0;
  int64_t count_ = 0;
  int64_t overruns_ = 0;
  double sum_ = 0.0;
  double max_ = 0.0;
  double last_ = 0.0;
  int64_t total_count_ = 0;
  // Run-long sample: every `stride_`-th duration, the stride doubling when full.
  std::vector<double> all_;
  int64_t stride_ = 1;
  double total_sum_ = 0.0;
  double total_max_ = 0.0;
  int64_t total_overruns_ = 0;
};

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_TIMING_STATS_H_
