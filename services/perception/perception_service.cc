#include "services/perception/perception_service.h"

#include <cstdio>

#include "common/util/logging.h"
#include "common/util/request_path.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "mbslam/snapshot_request_t.hpp"

namespace mbslam {

PerceptionService::PerceptionService(const PerceptionOptions& options) : options_(options) {}

std::unique_ptr<PerceptionService> PerceptionService::Create(const PerceptionOptions& options,
                                                             Status* status, LcmBus* bus) {
  if (!options.Check()) {
    *status = Status::Error(LastOptionError());
    return nullptr;
  }
  std::unique_ptr<PerceptionService> s(new PerceptionService(options));
  if (bus == nullptr) {
    s->owned_bus_ = LcmBus::Create(options.service.lcm_url, status);
    if (!s->owned_bus_) return nullptr;
    bus = s->owned_bus_.get();
  }
  s->bus_ = bus;
  if (!options.service.output_log.empty()) {
    s->output_log_ = LcmLogWriter::Open(options.service.output_log, status);
    if (!s->output_log_) return nullptr;
  }
  s->core_ = std::make_unique<PerceptionCore>(options.core(), &s->counters_, &s->timers_);
  s->lcm_sink_ = std::make_unique<LcmOutputSink>(bus, s->output_log_.get(), options.channels,
                                                 options.service.publish_tracks);
  s->sink_ = std::make_unique<TeeSink>(std::vector<OutputSink*>{s->lcm_sink_.get(), &s->recorder_});
  s->pipeline_ = std::make_unique<PerceptionPipeline>(options.pipeline, s->core_.get(),
                                                      s->sink_.get(), &s->counters_, &s->timers_);
  s->adapter_ = InputAdapter::Create(options.input, options.pipeline, s->pipeline_.get(),
                                     &s->counters_, status);
  if (!s->adapter_) return nullptr;
  PerceptionService* self = s.get();
  s->adapter_->set_snapshot_callback([self](const std::string& prefix, int what) {
    if (what & mbslam::snapshot_request_t::WHAT_GLOBAL_BA)
      self->core_->RequestGlobalBundleAdjustment();
    if ((what & mbslam::snapshot_request_t::WHAT_OUTPUTS) == 0) return;
    const std::string& output_dir = self->options_.service.output_dir;
    if (prefix.empty()) {
      self->WriteOutputs(output_dir);
      return;
    }
    // LCM has no authentication: a request names a folder under output_dir, never an
    // arbitrary place (absolute paths and ".." are refused and counted).
    std::string dir;
    const Status where = ResolveRequestPath(output_dir, prefix, /*allow_any_path=*/false, &dir);
    if (!where.ok()) {
      self->counters_.Increment("snapshot_request_refused_path");
      MBSLAM_LOG(WARNING) << "SNAPSHOT_REQUEST refused: " << where.message();
      return;
    }
    self->WriteOutputs(dir);
  });
  s->adapter_->Subscribe(bus, options.channels);
  s->from_log_ = options.service.lcm_url.rfind("file://", 0) == 0;
  s->last_status_wall_ = WallUtime();
  s->pipeline_->Start();
  s->started_ = true;
  *status = Status::Ok();
  return s;
}

PerceptionService::~PerceptionService() { Finish(); }

Status PerceptionService::WriteOutputs(const std::string& dir) {
  if (dir.empty()) return Status::Ok();
  std::string counters;
  for (const auto& [name, value] : counters_.Snapshot()) {
    counters += (counters.empty() ? "" : ", ") + ("\"" + name + "\": " + std::to_string(value));
  }
  std::string timings;
  for (const StageStatus& st : pipeline_->RunTimings()) {
    char buf[256];
    std::snprintf(buf, sizeof(buf),
                  "\"%s\": {\"count\": %lld, \"mean_ms\": %.3f, \"p50_ms\": %.3f, \"p99_ms\": %.3f, \"max_ms\": %.3f}",
                  st.name.c_str(), static_cast<long long>(st.timing.count), st.timing.mean_ms,
                  st.timing.p50_ms, st.timing.p99_ms, st.timing.max_ms);
    timings += (timings.empty() ? "" : ", ") + std::string(buf);
  }
  const Status s = recorder_.Write(
      dir, "\"counters\": {" + counters + "},\n  \"timings\": {" + timings + "}");
  if (!s.ok()) MBSLAM_LOG(ERROR) << "writing outputs to " << dir << ": " << s.message();
  else MBSLAM_LOG(INFO) << "outputs written to " << dir;
  return s;
}

void PerceptionService::MaybePublishStatus() {
  const int64_t now_wall = WallUtime();
  const int64_t now_utime = adapter_->last_image_utime();
  const int64_t period = options_.pipeline.status_period_us;
  // 1 Hz of message time while images flow; 1 Hz of wall time when they do not, so a
  // dead camera is reported as STALLED.
  const bool by_message_time = now_utime != 0 && now_utime - last_status_utime_ >= period;
  const bool by_wall_time = now_wall - last_status_wall_ >= period && (!from_log_ || now_utime == 0);
  if (!by_message_time && !by_wall_time) return;
  last_status_ = pipeline_->BuildStatus(now_wall);
  last_status_.results_kept_bytes = recorder_.RetainedBytes();
  lcm_sink_->PublishStatus(last_status_);
  last_status_utime_ = now_utime;
  last_status_wall_ = now_wall;
}

bool PerceptionService::RunOnce(int timeout_ms) {
  const int handled = bus_->HandleTimeout(timeout_ms);
  MaybePublishStatus();
  if (handled < 0) {
    if (from_log_ && options_.service.exit_at_end_of_log) return false;
    MBSLAM_LOG(ERROR) << "LCM handle failed";
  }
  return true;
}

Status PerceptionService::Run() {
  MBSLAM_LOG(INFO) << "running on "
                   << (options_.service.lcm_url.empty() ? "the LCM default URL" : options_.service.lcm_url)
                   << " in " << options_.pipeline.mode << " mode";
  while (!shutdown_ && !ShutdownRequested()) {
    if (!RunOnce(50)) break;
  }
  MBSLAM_LOG(INFO) << "stopping" << (ShutdownSignal() ? " on signal" : "");
  return Finish();
}

Status PerceptionService::Finish() {
  // A service whose Create() failed half way (no bus, a bad calibration file) has
  // nothing to finish; its destructor used to dereference the missing pipeline.
  if (finished_ || !started_) return Status::Ok();
  finished_ = true;
  pipeline_->Stop();
  last_status_ = pipeline_->BuildStatus(WallUtime());
  last_status_.results_kept_bytes = recorder_.RetainedBytes();
  lcm_sink_->PublishStatus(last_status_);
  if (output_log_) output_log_->Flush();
  MBSLAM_LOG(INFO) << "frames received " << last_status_.frames_received << ", processed "
                   << last_status_.frames_processed << ", dropped " << last_status_.frames_dropped
                   << ", rejected " << last_status_.frames_rejected;
  auto mb = [](int64_t bytes) { return bytes < 0 ? std::string("unknown") : std::to_string(bytes >> 20) + " MB"; };
  MBSLAM_LOG(INFO) << "memory: resident " << mb(last_status_.memory.rss_bytes) << ", heap in use "
                   << mb(last_status_.memory.heap_in_use_bytes) << ", heap held "
                   << mb(last_status_.memory.heap_held_bytes) << ", kept for the output files "
                   << mb(last_status_.results_kept_bytes);
  for (const auto& [name, value] : last_status_.counters) {
    MBSLAM_LOG(INFO) << "  " << name << ": " << value;
  }
  for (const StageStatus& st : pipeline_->RunTimings()) {
    MBSLAM_LOG(INFO) << "  stage " << st.name << ": n " << st.timing.count << " mean "
                     << st.timing.mean_ms << " ms, p50 " << st.timing.p50_ms << " ms, p99 "
                     << st.timing.p99_ms << " ms, max " << st.timing.max_ms << " ms";
  }
  return WriteOutputs(options_.service.output_dir);
}

}  // namespace mbslam
