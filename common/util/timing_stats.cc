#include "common/util/timing_stats.h"

#include <algorithm>
#include <cmath>

namespace mbslam {

double Percentile(std::vector<double>* values, double percent) {
  if (values->empty()) return 0.0;
  std::sort(values->begin(), values->end());
  const double clamped = std::min(100.0, std::max(0.0, percent));
  const double rank = clamped / 100.0 * static_cast<double>(values->size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(rank));
  const size_t hi = std::min(values->size() - 1, lo + 1);
  const double frac = rank - static_cast<double>(lo);
  return (*values)[lo] * (1.0 - frac) + (*values)[hi] * frac;
}

TimingStats::TimingStats(std::string name, double budget_ms, size_t max_samples)
    : name_(std::move(name)), budget_ms_(budget_ms), max_samples_(std::max<size_t>(1, max_samples)) {
  samples_.reserve(std::min<size_t>(max_samples_, 1024));
}

void TimingStats::Add(double duration_ms) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (samples_.size() < max_samples_) {
    samples_.push_back(duration_ms);
  } else {
    samples_[next_] = duration_ms;
    next_ = (next_ + 1) % max_samples_;
  }
  ++count_;
  ++total_count_;
  last_ = duration_ms;
  sum_ += duration_ms;
  max_ = std::max(max_, duration_ms);
  if (budget_ms_ > 0.0 && duration_ms > budget_ms_) {
    ++overruns_;
    ++total_overruns_;
  }
  total_sum_ += duration_ms;
  total_max_ = std::max(total_max_, duration_ms);
  if ((total_count_ - 1) % stride_ == 0) {
    all_.push_back(duration_ms);
    if (all_.size() >= 2 * max_samples_) {
      // Keep every other sample and halve the rate.
      for (size_t i = 0; i < all_.size() / 2; ++i) all_[i] = all_[2 * i];
      all_.resize(all_.size() / 2);
      stride_ *= 2;
    }
  }
}

TimingSummary TimingStats::Cumulative() const {
  std::vector<double> samples;
  TimingSummary summary;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    samples = all_;
    summary.count = total_count_;
    summary.mean_ms = total_count_ > 0 ? total_sum_ / static_cast<double>(total_count_) : 0.0;
    summary.max_ms = total_max_;
    summary.overruns = total_overruns_;
  }
  summary.p50_ms = Percentile(&samples, 50.0);
  summary.p99_ms = Percentile(&samples, 99.0);
  return summary;
}

TimingSummary TimingStats::Drain() {
  std::vector<double> samples;
  TimingSummary summary;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    samples.swap(samples_);
    summary.count = count_;
    summary.mean_ms = count_ > 0 ? sum_ / static_cast<double>(count_) : 0.0;
    summary.max_ms = max_;
    summary.overruns = overruns_;
    count_ = 0;
    overruns_ = 0;
    sum_ = 0.0;
    max_ = 0.0;
    next_ = 0;
  }
  summary.p50_ms = Percentile(&samples, 50.0);
  summary.p99_ms = Percentile(&samples, 99.0);
  return summary;
}

int64_t TimingStats::total_count() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return total_count_;
}

double TimingStats::last_ms() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_;
}

}  // namespace mbslam
