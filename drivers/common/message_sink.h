#ifndef MBSLAM_DRIVERS_COMMON_MESSAGE_SINK_H_
#define MBSLAM_DRIVERS_COMMON_MESSAGE_SINK_H_

// Where a driver's messages go: a live LCM bus, or an LCM log file written directly
// with the message time as event time (so the same input gives the same log bytes).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/lcm/lcm_bus.h"
#include "common/lcm/lcm_log.h"
#include "common/util/status.h"

namespace mbslam {

class MessageSink {
 public:
  virtual ~MessageSink() = default;

  // Publishes encoded bytes; `utime` is the message time (µs).
  virtual Status PublishRaw(const std::string& channel, int64_t utime, const void* data,
                            size_t size) = 0;
  virtual void Flush() {}
  // True when messages go to a file (no pacing is needed).
  virtual bool is_file() const = 0;
  virtual std::string description() const = 0;

  template <typename Msg>
  Status Publish(const std::string& channel, int64_t utime, const Msg& msg) {
    const int size = msg.getEncodedSize();
    if (size < 0) return Status::Error("cannot size a " + std::string(Msg::getTypeName()));
    buffer_.resize(static_cast<size_t>(size));
    if (msg.encode(buffer_.data(), 0, size) != size) {
      return Status::Error("encoding " + std::string(Msg::getTypeName()) + " failed");
    }
    return PublishRaw(channel, utime, buffer_.data(), buffer_.size());
  }

  int64_t messages() const { return messages_; }

 protected:
  int64_t messages_ = 0;

 private:
  std::vector<uint8_t> buffer_;
};

// Publishes on an LCM bus the sink owns (or borrows).
class LcmBusSink : public MessageSink {
 public:
  static std::unique_ptr<LcmBusSink> Create(const std::string& url, Status* status);
  // Borrows a bus that outlives the sink (tests, a process that also subscribes).
  explicit LcmBusSink(LcmBus* bus) : bus_(bus) {}

  Status PublishRaw(const std::string& channel, int64_t utime, const void* data,
                    size_t size) override;
  bool is_file() const override { return false; }
  std::string description() const override { return "LCM " + bus_->url(); }
  LcmBus* bus() { return bus_; }

 private:
  explicit LcmBusSink(std::unique_ptr<LcmBus> bus) : owned_(std::move(bus)), bus_(owned_.get()) {}
  std::unique_ptr<LcmBus> owned_;
  LcmBus* bus_;
};

// Writes an LCM log file; event timestamp = message utime.
class LcmLogSink : public MessageSink {
 public:
  static std::unique_ptr<LcmLogSink> Create(const std::string& path, Status* status);

  Status PublishRaw(const std::string& channel, int64_t utime, const void* data,
                    size_t size) override;
  void Flush() override { writer_->Flush(); }
  bool is_file() const override { return true; }
  std::string description() const override { return "log " + path_; }

 private:
  LcmLogSink(std::unique_ptr<LcmLogWriter> writer, std::string path)
      : writer_(std::move(writer)), path_(std::move(path)) {}
  std::unique_ptr<LcmLogWriter> writer_;
  std::string path_;
};

// Opens a log sink when `log_path` is non-empty, else a bus sink on `lcm_url`.
std::unique_ptr<MessageSink> CreateMessageSink(const std::string& log_path,
                                               const std::string& lcm_url, Status* status);

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_MESSAGE_SINK_H_
