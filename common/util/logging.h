#ifndef MBSLAM_COMMON_UTIL_LOGGING_H_
#define MBSLAM_COMMON_UTIL_LOGGING_H_

// Minimal thread-safe logging to stderr:  MBSLAM_LOG(INFO) << "x = " << x;
// Each statement is written with a single write, so lines from threads never mix.

#include <sstream>
#include <string>

namespace mbslam {

enum class LogLevel { kDebug = 0, kInfo = 1, kWarning = 2, kError = 3 };

void SetLogLevel(LogLevel level);
LogLevel GetLogLevel();
// Parses "debug", "info", "warning", "error"; returns false on anything else.
bool ParseLogLevel(const std::string& text, LogLevel* level);

namespace internal {

class LogMessage {
 public:
  LogMessage(LogLevel level, const char* file, int line);
  ~LogMessage();
  std::ostream& stream() { return stream_; }

 private:
  LogLevel level_;
  std::ostringstream stream_;
};

// Swallows the stream when the level is disabled.
struct LogVoidify {
  void operator&(std::ostream&) {}
};

}  // namespace internal
}  // namespace mbslam

#define MBSLAM_LOG_LEVEL_DEBUG ::mbslam::LogLevel::kDebug
#define MBSLAM_LOG_LEVEL_INFO ::mbslam::LogLevel::kInfo
#define MBSLAM_LOG_LEVEL_WARNING ::mbslam::LogLevel::kWarning
#define MBSLAM_LOG_LEVEL_ERROR ::mbslam::LogLevel::kError

#define MBSLAM_LOG(level)                                                   \
  (MBSLAM_LOG_LEVEL_##level < ::mbslam::GetLogLevel())                      \
      ? (void)0                                                             \
      : ::mbslam::internal::LogVoidify() &                                  \
            ::mbslam::internal::LogMessage(MBSLAM_LOG_LEVEL_##level, __FILE__, __LINE__) \
                .stream()

#endif  // MBSLAM_COMMON_UTIL_LOGGING_H_
