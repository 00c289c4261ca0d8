#include "drivers/common/message_sink.h"

#include <limits>

namespace mbslam {

std::unique_ptr<LcmBusSink> LcmBusSink::Create(const std::string& url, Status* status) {
  std::unique_ptr<LcmBus> bus = LcmBus::Create(url, status);
  if (!bus) return nullptr;
  return std::unique_ptr<LcmBusSink>(new LcmBusSink(std::move(bus)));
}

Status LcmBusSink::PublishRaw(const std::string& channel, int64_t /*utime*/, const void* data,
                              size_t size) {
  if (size > std::numeric_limits<unsigned>::max()) {
    return Status::Error("message on " + channel + " too large");
  }
  if (bus_->PublishRaw(channel, data, static_cast<unsigned>(size)) != 0) {
    return Status::Error("publishing on " + channel + " via " + bus_->url() + " failed");
  }
  ++messages_;
  return Status::Ok();
}

std::unique_ptr<LcmLogSink> LcmLogSink::Create(const std::string& path, Status* status) {
  std::unique_ptr<LcmLogWriter> writer = LcmLogWriter::Open(path, status);
  if (!writer) return nullptr;
  return std::unique_ptr<LcmLogSink>(new LcmLogSink(std::move(writer), path));
}

Status LcmLogSink::PublishRaw(const std::string& channel, int64_t utime, const void* data,
                              size_t size) {
  MBSLAM_RETURN_IF_ERROR(writer_->WriteRaw(channel, utime, data, size).WithContext(path_));
  ++messages_;
  return Status::Ok();
}

std::unique_ptr<MessageSink> CreateMessageSink(const std::string& log_path,
                                               const std::string& lcm_url, Status* status) {
  if (!log_path.empty()) return LcmLogSink::Create(log_path, status);
  return LcmBusSink::Create(lcm_url, status);
}

}  // namespace mbslam
