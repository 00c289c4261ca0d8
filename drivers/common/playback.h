#ifndef MBSLAM_DRIVERS_COMMON_PLAYBACK_H_
#define MBSLAM_DRIVERS_COMMON_PLAYBACK_H_

// Pacing of recorded data against the wall clock, and a terminal progress bar.

#include <cstdint>
#include <cstdio>
#include <string>

namespace mbslam {

// Releases messages at `speed` times their recorded rate: message time t is due at
// wall time start + (t - t0) / speed, t0 being the first message time seen. speed = 0
// means as fast as possible. Sleeps in short slices and returns early on shutdown.
class PlaybackClock {
 public:
  explicit PlaybackClock(double speed) : speed_(speed) {}

  // Waits until message time `utime` is due. Returns false if shutdown was requested.
  bool WaitUntil(int64_t utime);
  // Forgets the time origin (the next WaitUntil starts a new one), e.g. after a pause.
  void Reset() { started_ = false; }
  double speed() const { return speed_; }
  // How far behind schedule the last WaitUntil was (µs, 0 when on time).
  int64_t last_lag_us() const { return last_lag_us_; }

 private:
  double speed_;
  bool started_ = false;
  int64_t t0_utime_ = 0;
  int64_t start_mono_us_ = 0;
  int64_t last_lag_us_ = 0;
};

// "[=====>    ] 45/189  23.8 %  frames/s  bad 0" on one refreshed line. Draws only when
// enabled and the stream is a terminal; redraws at most 10 times a second.
class ProgressBar {
 public:
  ProgressBar(bool enabled, FILE* stream = stderr);
  ~ProgressBar();

  // `total` < 0 when unknown (then only the count is shown).
  void Update(int64_t done, int64_t total, const std::string& note = "");
  // Clears the line (before other output, and at the end).
  void Finish();
  bool active() const { return active_; }

 private:
  FILE* stream_;
  bool active_;
  bool drawn_ = false;
  int64_t last_draw_us_ = 0;
  int64_t start_us_ = 0;
};

// True if `stream` is a terminal.
bool IsTerminal(FILE* stream);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_PLAYBACK_H_
