#ifndef MBSLAM_COMMON_UTIL_SHUTDOWN_H_
#define MBSLAM_COMMON_UTIL_SHUTDOWN_H_

// Clean shutdown on SIGINT / SIGTERM: the handler only sets a flag; main loops poll
// ShutdownRequested() between handleTimeout() calls.

namespace mbslam {

// Installs handlers for SIGINT and SIGTERM (and ignores SIGPIPE). Idempotent.
void InstallShutdownHandlers();

bool ShutdownRequested();

// Lets code other than a signal ask for shutdown (end of a log, fatal input error).
void RequestShutdown();

// The signal that asked for shutdown, 0 if none.
int ShutdownSignal();

}  // namespace mbslam

#endif  // MBSLAM_COMMON_UTIL_SHUTDOWN_H_
