#include "services/perception/pipeline/pipeline.h"

#include <limits>

#include "common/util/logging.h"
#include "common/util/time.h"
#include "services/perception/pipeline/image_decode.h"

namespace mbslam {

const char* ServiceStateName(ServiceState state) {
  switch (state) {
    case ServiceState::kStarting: return "starting";
    case ServiceState::kRunning: return "running";
    case ServiceState::kDegraded: return "degraded";
    case ServiceState::kStalled: return "stalled";
    case ServiceState::kStopping: return "stopping";
  }
  return "unknown";
}

const char* TrackingStateName(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized: return "not_initialized";
    case TrackingState::kInitializing: return "initializing";
    case TrackingState::kOk: return "ok";
    case TrackingState::kLost: return "lost";
    case TrackingState::kRelocalized: return "relocalized";
  }
  return "unknown";
}

namespace {
QueueFullPolicy ImagePolicy(const PipelineOptions& o) {
  return o.lockstep() ? QueueFullPolicy::kBlock : QueueFullPolicy::kDropOldest;
}
}  // namespace

PerceptionPipeline::PerceptionPipeline(const PipelineOptions& options, FrameProcessor* processor,
                                       OutputSink* sink, Counters* counters, StageTimers* timers)
    : options_(options),
      processor_(processor),
      sink_(sink),
      counters_(counters),
      timers_(timers),
      decode_timer_(timers->Get("decode")),
      publish_timer_(timers->Get("publish")),
      frame_timer_(timers->Get("frame_total", options.frame_budget_ms)),
      latency_("latency"),
      input_queue_(options.lockstep() ? options.lockstep_queue_capacity : options.image_queue_capacity,
                   ImagePolicy(options)),
      frame_queue_(options.lockstep() ? 4 : 1, ImagePolicy(options)),
      odometry_queue_(options.aux_queue_capacity, QueueFullPolicy::kDropOldest) {}

PerceptionPipeline::~PerceptionPipeline() { Stop(); }

void PerceptionPipeline::Start() {
  if (started_) return;
  started_ = true;
  period_start_wall_ = WallUtime();
  if (!options_.timing_log.empty()) {
    timing_log_.open(options_.timing_log, std::ios::trunc);
    if (!timing_log_) MBSLAM_LOG(WARNING) << "timing log " << options_.timing_log << ": cannot open; not written";
  }
  decode_thread_ = std::thread([this] { DecodeLoop(); });
  process_thread_ = std::thread([this] { ProcessLoop(); });
}

void PerceptionPipeline::Stop() {
  if (!started_ || stopped_) return;
  stopped_ = true;
  if (!options_.lockstep()) {
    // Realtime: what is still queued will not be processed; count it.
    int64_t left = 0;
    while (auto e = input_queue_.TryPop()) {
      if (std::holds_alternative<RawImage>(*e)) ++left;
    }
    if (left > 0) counters_->Increment(counter::kImageDroppedStale, left);
  }
  input_queue_.Shutdown();  // the decode thread drains what remains, then ends
  decode_thread_.join();
  frame_queue_.Shutdown();
  odometry_queue_.Shutdown();
  process_thread_.join();
  processor_->Finish();
  const std::vector<std::pair<int64_t, Rigid3d>> adjusted = processor_->AdjustedCameraTrajectory();
  if (!adjusted.empty()) sink_->OnAdjustedCameraTrajectory(adjusted);
}

void PerceptionPipeline::Push(InputEvent event) {
  if (auto* image = std::get_if<RawImage>(&event)) {
    ++frames_received_;
    latest_utime_.store(image->utime);
    last_image_wall_utime_.store(image->receive_wall_utime);
  } else if (auto* odom = std::get_if<OdometrySample>(&event)) {
    latest_utime_.store(std::max(latest_utime_.load(), odom->utime));
    if (!options_.lockstep()) {
      odometry_queue_.Push(std::move(*odom));
      return;
    }
  }
  const int64_t dropped_before = input_queue_.dropped();
  input_queue_.Push(std::move(event));
  const int64_t dropped = input_queue_.dropped() - dropped_before;
  if (dropped > 0) counters_->Increment(counter::kImageDroppedStale, dropped);
}

void PerceptionPipeline::DecodeLoop() {
  while (auto event = input_queue_.Pop()) {
    if (auto* odom = std::get_if<OdometrySample>(&*event)) {
      frame_queue_.Push(FrameEvent(std::move(*odom)));
      continue;
    }
    const RawImage& raw = std::get<RawImage>(*event);
    ImageFrame frame;
    Status status;
    {
      ScopedStageTimer timer(decode_timer_);
      status = DecodeImage(raw, /*keep_color=*/true, &frame);
    }
    if (!status.ok()) {
      counters_->Increment(counter::kImageDecompressError);
      ++frames_rejected_;
      MBSLAM_LOG(WARNING) << "image seq " << raw.seq << " rejected: " << status.message();
      continue;
    }
    frame.intrinsics = raw.intrinsics;
    frame.timeline_reset = raw.timeline_reset;
    const int64_t dropped_before = frame_queue_.dropped();
    frame_queue_.Push(FrameEvent(std::move(frame)));
    const int64_t dropped = frame_queue_.dropped() - dropped_before;
    if (dropped > 0) counters_->Increment(counter::kImageDroppedStale, dropped);
  }
}

void PerceptionPipeline::DrainOdometry() {
  while (auto odom = odometry_queue_.TryPop()) processor_->OnOdometry(*odom);
}

void PerceptionPipeline::ProcessImage(const ImageFrame& frame) {
  const int64_t start_wall = WallUtime();
  FrameResult result;
  {
    ScopedStageTimer timer(frame_timer_);
    result = processor_->ProcessFrame(frame);
  }
  result.receive_wall_utime = frame.receive_wall_utime;
  CountTrackingTransition(result.camera_pose.tracking_state);
  {
    ScopedStageTimer timer(publish_timer_);
    sink_->OnFrameResult(result);
  }
  ++frames_processed_;
  const int64_t end_wall = WallUtime();
  if (frame.receive_wall_utime > 0) {
    latency_.Add(UtimeToMs(end_wall - frame.receive_wall_utime));
  }
  if (timing_log_.is_open()) WriteTimingLine(frame, start_wall, end_wall);
}

void PerceptionPipeline::WriteTimingLine(const ImageFrame& frame, int64_t start_wall_utime, int64_t end_wall_utime) {
  if (timing_log_stages_.empty()) {
    timing_log_stages_ = timers_->All();
    timing_log_counts_.assign(timing_log_stages_.size(), 0);
    timing_log_ << "seq,utime,wait_ms";
    for (const TimingStats* s : timing_log_stages_) timing_log_ << "," << s->name() << "_ms";
    timing_log_ << ",latency_ms\n";
  }
  const bool received = frame.receive_wall_utime > 0;
  timing_log_ << frame.seq << "," << frame.utime << ","
              << (received ? UtimeToMs(start_wall_utime - frame.receive_wall_utime) : 0.0);
  // A stage that did not run in this image (or, for a back-end stage, did not finish
  // during it) is written as 0.
  for (size_t i = 0; i < timing_log_stages_.size(); ++i) {
    const int64_t count = timing_log_stages_[i]->total_count();
    timing_log_ << "," << (count != timing_log_counts_[i] ? timing_log_stages_[i]->last_ms() : 0.0);
    timing_log_counts_[i] = count;
  }
  timing_log_ << "," << (received ? UtimeToMs(end_wall_utime - frame.receive_wall_utime) : 0.0) << "\n";
}

void PerceptionPipeline::CountTrackingTransition(TrackingState state) {
  const bool tracked = state == TrackingState::kOk || state == TrackingState::kRelocalized;
  if (tracked && !was_tracked_ && ever_tracked_) counters_->Increment(counter::kTrackingRecovered);
  if (!tracked && was_tracked_) counters_->Increment(counter::kTrackingLost);
  ever_tracked_ = ever_tracked_ || tracked;
  was_tracked_ = tracked;
  tracking_state_.store(static_cast<int>(state));
}

void PerceptionPipeline::ProcessLoop() {
  // Lockstep: when the log carries odometry, an image waits until odometry covering its
  // time has been processed (or the next image arrives), so that it is interpolated,
  // not extrapolated — the same decision on every replay, since it depends only on the
  // order of the log.
  std::optional<ImageFrame> pending;
  bool odometry_in_log = false;
  int64_t last_odometry_utime = std::numeric_limits<int64_t>::min();
  while (true) {
    std::optional<FrameEvent> event =
        options_.lockstep() ? frame_queue_.Pop() : frame_queue_.PopFor(20000);
    if (!options_.lockstep()) DrainOdometry();
    if (!event) {
      if (frame_queue_.is_shutdown()) break;
      continue;
    }
    if (auto* odom = std::get_if<OdometrySample>(&*event)) {
      processor_->OnOdometry(*odom);
      odometry_in_log = true;
      last_odometry_utime = std::max(last_odometry_utime, odom->utime);
      if (pending && last_odometry_utime >= pending->utime) {
        ProcessImage(*pending);
        pending.reset();
      }
      continue;
    }
    ImageFrame& frame = std::get<ImageFrame>(*event);
    if (pending) {
      ProcessImage(*pending);
      pending.reset();
    }
    // A new timeline (time went back for good): its first image goes through at once,
    // so that the processor starts over before the new timeline's odometry reaches it;
    // the old timeline's odometry covers none of the images after it.
    if (frame.timeline_reset) {
      ProcessImage(frame);
      last_odometry_utime = std::numeric_limits<int64_t>::min();
      continue;
    }
    if (options_.lockstep() && odometry_in_log && last_odometry_utime < frame.utime) {
      pending = std::move(frame);
      continue;
    }
    ProcessImage(frame);
  }
  if (pending) ProcessImage(*pending);
}

std::vector<StageStatus> PerceptionPipeline::RunTimings() const {
  std::vector<StageStatus> out;
  for (TimingStats* stage : timers_->All()) out.push_back(StageStatus{stage->name(), stage->Cumulative()});
  out.push_back(StageStatus{"latency", latency_.Cumulative()});
  return out;
}

PipelineStatus PerceptionPipeline::BuildStatus(int64_t wall_utime) {
  PipelineStatus s;
  s.utime = latest_utime_.load();
  s.wall_utime = wall_utime;
  s.lockstep = options_.lockstep();
  s.frames_received = frames_received_.load();
  s.frames_processed = frames_processed_.load();
  s.frames_rejected = frames_rejected_.load();
  s.frames_dropped = counters_->Get(counter::kImageDroppedStale);

  const double wall_span = UtimeToSeconds(wall_utime - period_start_wall_);
  if (wall_span > 0.0) {
    s.processed_fps = static_cast<double>(s.frames_processed - period_start_processed_) / wall_span;
  }
  const double msg_span = UtimeToSeconds(s.utime - period_first_utime_);
  if (period_first_utime_ > 0 && msg_span > 0.0) {
    s.input_fps = static_cast<double>(s.frames_received - period_start_received_) / msg_span;
  }
  period_start_wall_ = wall_utime;
  period_start_processed_ = s.frames_processed;
  period_start_received_ = s.frames_received;
  period_first_utime_ = s.utime;

  const TimingSummary latency = latency_.Drain();
  s.latency_p50_ms = latency.p50_ms;
  s.latency_p99_ms = latency.p99_ms;
  // The heap figures at most every heap_stats_period_us (mallinfo2 holds the allocator's
  // locks); in between, the last ones with a fresh resident set.
  const bool heap_due = options_.heap_stats_period_us > 0 &&
                        (heap_sampled_wall_ == 0 || wall_utime - heap_sampled_wall_ >= options_.heap_stats_period_us);
  const ProcessMemory now = SampleProcessMemory(heap_due);
  if (heap_due) {
    memory_ = now;
    heap_sampled_wall_ = wall_utime;
  }
  memory_.rss_bytes = now.rss_bytes;
  s.memory = memory_;
  for (TimingStats* stage : timers_->All()) {
    StageStatus st{stage->name(), stage->Drain()};
    if (st.timing.overruns > 0) counters_->Increment(counter::kStageOverrun, st.timing.overruns);
    s.stages.push_back(st);
  }
  s.queues.push_back(QueueStatus{"input", static_cast<int>(input_queue_.size()),
                                 static_cast<int>(input_queue_.capacity()), input_queue_.dropped()});
  s.queues.push_back(QueueStatus{"frames", static_cast<int>(frame_queue_.size()),
                                 static_cast<int>(frame_queue_.capacity()), frame_queue_.dropped()});
  s.queues.push_back(QueueStatus{"odometry", static_cast<int>(odometry_queue_.size()),
                                 static_cast<int>(odometry_queue_.capacity()),
                                 odometry_queue_.dropped()});
  s.counters = counters_->Snapshot();

  const int64_t last_image = last_image_wall_utime_.load();
  if (stopped_) {
    s.state = ServiceState::kStopping;
    s.message = "stopping";
  } else if (s.frames_received == 0) {
    s.state = ServiceState::kStarting;
    s.message = "waiting for images";
  } else if (!options_.lockstep() && wall_utime - last_image > options_.stall_timeout_us) {
    s.state = ServiceState::kStalled;
    s.message = "no image for " + std::to_string((wall_utime - last_image) / 1000) + " ms";
  } else {
    // Degraded when an error or drop counter moved during the period.
    std::string moved;
    for (const auto& [name, value] : s.counters) {
      int64_t before = 0;
      for (const auto& [pname, pvalue] : previous_counters_) {
        if (pname == name) before = pvalue;
      }
      if (value > before && !IsInformationalCounter(name)) {
        moved += (moved.empty() ? "" : ", ") + name + " +" + std::to_string(value - before);
      }
    }
    s.state = moved.empty() ? ServiceState::kRunning : ServiceState::kDegraded;
    s.message = moved.empty() ? "running" : moved;
    const auto tracking = static_cast<TrackingState>(tracking_state_.load());
    if (s.frames_processed > 0 && tracking != TrackingState::kOk && tracking != TrackingState::kRelocalized) {
      s.message += std::string("; tracking ") + TrackingStateName(tracking);
    }
  }
  previous_counters_ = s.counters;
  return s;
}

}  // namespace mbslam
