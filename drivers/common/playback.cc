#include "drivers/common/playback.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <thread>

#include "common/util/shutdown.h"
#include "common/util/time.h"

namespace mbslam {

bool PlaybackClock::WaitUntil(int64_t utime) {
  if (ShutdownRequested()) return false;
  last_lag_us_ = 0;
  if (speed_ <= 0.0) return true;
  const int64_t now = MonotonicUtime();
  if (!started_ || utime < t0_utime_) {
    // First message, or time went backwards (a new loop): restart the schedule.
    started_ = true;
    t0_utime_ = utime;
    start_mono_us_ = now;
    return true;
  }
  const int64_t due = start_mono_us_ + static_cast<int64_t>(std::llround(
                                           static_cast<double>(utime - t0_utime_) / speed_));
  constexpr int64_t kSliceUs = 50000;  // re-check shutdown this often
  for (int64_t t = MonotonicUtime(); t < due; t = MonotonicUtime()) {
    if (ShutdownRequested()) return false;
    std::this_thread::sleep_for(std::chrono::microseconds(std::min(due - t, kSliceUs)));
  }
  last_lag_us_ = std::max<int64_t>(0, MonotonicUtime() - due);
  return !ShutdownRequested();
}

bool IsTerminal(FILE* stream) { return stream != nullptr && isatty(fileno(stream)) == 1; }

ProgressBar::ProgressBar(bool enabled, FILE* stream)
    : stream_(stream), active_(enabled && IsTerminal(stream)), start_us_(MonotonicUtime()) {}

ProgressBar::~ProgressBar() { Finish(); }

void ProgressBar::Update(int64_t done, int64_t total, const std::string& note) {
  if (!active_) return;
  const int64_t now = MonotonicUtime();
  const bool last = total > 0 && done >= total;
  if (drawn_ && !last && now - last_draw_us_ < 100000) return;
  last_draw_us_ = now;
  const double elapsed_s = std::max(1e-6, UtimeToSeconds(now - start_us_));
  const double rate = static_cast<double>(done) / elapsed_s;
  char line[256];
  if (total > 0) {
    constexpr int kWidth = 30;
    const double fraction = std::min(1.0, static_cast<double>(done) / static_cast<double>(total));
    const int filled = static_cast<int>(fraction * kWidth);
    std::string bar(static_cast<size_t>(filled), '=');
    if (filled < kWidth) bar += '>';
    bar.resize(kWidth, ' ');
    std::snprintf(line, sizeof(line), "\r[%s] %lld/%lld %5.1f %% %6.1f/s %s", bar.c_str(),
                  static_cast<long long>(done), static_cast<long long>(total), 100.0 * fraction,
                  rate, note.c_str());
  } else {
    std::snprintf(line, sizeof(line), "\r%lld %6.1f/s %s", static_cast<long long>(done), rate,
                  note.c_str());
  }
  std::fputs(line, stream_);
  std::fputs("\033[K", stream_);  // clear the rest of the line
  std::fflush(stream_);
  drawn_ = true;
}

void ProgressBar::Finish() {
  if (!active_ || !drawn_) return;
  std::fputs("\r\033[K", stream_);
  std::fflush(stream_);
  drawn_ = false;
}

}  // namespace mbslam
