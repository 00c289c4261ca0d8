#include "common/lcm/lcm_log.h"

#include <cstdio>

namespace mbslam {

std::unique_ptr<LcmLogWriter> LcmLogWriter::Open(const std::string& path, Status* status) {
  auto file = std::make_unique<lcm::LogFile>(path, "w");
  if (!file->good()) {
    *status = Status::Error("cannot open LCM log " + path + " for writing");
    return nullptr;
  }
  *status = Status::Ok();
  return std::unique_ptr<LcmLogWriter>(new LcmLogWriter(std::move(file)));
}

Status LcmLogWriter::WriteRaw(const std::string& channel, int64_t timestamp, const void* data,
                              size_t size) {
  lcm::LogEvent event;
  event.eventnum = events_;
  event.timestamp = timestamp;
  event.channel = channel;
  event.datalen = static_cast<int32_t>(size);
  event.data = const_cast<void*>(data);
  if (file_->writeEvent(&event) != 0) return Status::Error("writing LCM log event failed");
  ++events_;
  return Status::Ok();
}

void LcmLogWriter::Flush() { std::fflush(file_->getFilePtr()); }

std::unique_ptr<LcmLogReader> LcmLogReader::Open(const std::string& path, Status* status) {
  auto file = std::make_unique<lcm::LogFile>(path, "r");
  if (!file->good()) {
    *status = Status::Error("cannot open LCM log " + path);
    return nullptr;
  }
  *status = Status::Ok();
  return std::unique_ptr<LcmLogReader>(new LcmLogReader(std::move(file)));
}

bool LcmLogReader::Next(LcmLogEvent* event) {
  const lcm::LogEvent* e = file_->readNextEvent();
  if (e == nullptr) return false;
  event->timestamp = e->timestamp;
  event->channel = e->channel;
  const auto* bytes = static_cast<const uint8_t*>(e->data);
  event->data.assign(bytes, bytes + e->datalen);
  return true;
}

Status ReadLcmLog(const std::string& path, std::vector<LcmLogEvent>* events,
                  const std::string& channel_filter) {
  Status status;
  auto reader = LcmLogReader::Open(path, &status);
  if (!reader) return status;
  LcmLogEvent event;
  while (reader->Next(&event)) {
    if (channel_filter.empty() || event.channel == channel_filter) events->push_back(event);
  }
  return Status::Ok();
}

}  // namespace mbslam
