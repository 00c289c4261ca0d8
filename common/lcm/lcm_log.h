#ifndef MBSLAM_COMMON_LCM_LCM_LOG_H_
#define MBSLAM_COMMON_LCM_LCM_LOG_H_

// Reading and writing LCM log files directly (no bus). The writer stamps each event
// with the time the caller gives (message time), so the same inputs give a
// byte-identical log — unlike lcm-logger, which stamps wall-clock receive time.

#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/util/status.h"

namespace mbslam {

struct LcmLogEvent {
  int64_t timestamp = 0;  // event time (µs)
  std::string channel;
  std::vector<uint8_t> data;
};

class LcmLogWriter {
 public:
  static std::unique_ptr<LcmLogWriter> Open(const std::string& path, Status* status);

  Status WriteRaw(const std::string& channel, int64_t timestamp, const void* data, size_t size);

  template <typename Msg>
  Status Write(const std::string& channel, int64_t timestamp, const Msg& msg) {
    std::vector<uint8_t> buf(static_cast<size_t>(msg.getEncodedSize()));
    if (msg.encode(buf.data(), 0, static_cast<int>(buf.size())) < 0) {
      return Status::Error("encoding " + std::string(Msg::getTypeName()) + " failed");
    }
    return WriteRaw(channel, timestamp, buf.data(), buf.size());
  }

  // Flushes buffered events to the file.
  void Flush();
  int64_t events_written() const { return events_; }

 private:
  explicit LcmLogWriter(std::unique_ptr<lcm::LogFile> file) : file_(std::move(file)) {}
  std::unique_ptr<lcm::LogFile> file_;
  int64_t events_ = 0;
};

class LcmLogReader {
 public:
  static std::unique_ptr<LcmLogReader> Open(const std::string& path, Status* status);

  // Next event, or false at the end of the log (or on a corrupt tail).
  bool Next(LcmLogEvent* event);

 private:
  explicit LcmLogReader(std::unique_ptr<lcm::LogFile> file) : file_(std::move(file)) {}
  std::unique_ptr<lcm::LogFile> file_;
};

// Reads every event of a log (optionally only one channel).
Status ReadLcmLog(const std::string& path, std::vector<LcmLogEvent>* events,
                  const std::string& channel_filter = "");

}  // namespace mbslam

#endif  // MBSLAM_COMMON_LCM_LCM_LOG_H_
