#include "drivers/camera/camera_driver.h"

#include <chrono>
#include <sstream>
#include <thread>

#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "drivers/camera/camera_messages.h"
#include "drivers/camera/dc1394_source.h"
#include "drivers/camera/image_list_source.h"
#include "drivers/camera/v4l2_source.h"
#include "drivers/camera/video_source.h"
#include "drivers/common/playback.h"

namespace mbslam {
namespace {

constexpr size_t kMaxBadFrameExamples = 5;

// Sleeps up to `seconds`, returning false early on shutdown.
bool SleepUnlessShutdown(double seconds) {
  const int64_t end = MonotonicUtime() + SecondsToUtime(seconds);
  while (MonotonicUtime() < end) {
    if (ShutdownRequested()) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return !ShutdownRequested();
}

bool Retryable(SourceError kind) {
  return kind == SourceError::kNoCamera || kind == SourceError::kDisconnected ||
         kind == SourceError::kAccess || kind == SourceError::kIo;
}

}  // namespace

std::unique_ptr<FrameSource> CreateFrameSource(const CameraDriverOptions& options) {
  const std::string& s = options.source;
  if (s == "dc1394") return std::make_unique<Dc1394Source>(options.dc1394);
  if (s == "v4l2") return std::make_unique<V4l2Source>(options.v4l2);
  if (s == "video") {
    return std::make_unique<VideoSource>(options.input, options.folder.rate_hz,
                                         SecondsToUtime(options.folder.time_origin_s));
  }
  return std::make_unique<ImageListSource>(s, options.input, options.folder, options.ground_truth);
}

CameraDriver::CameraDriver(CameraDriverOptions options, FrameSource* source, MessageSink* sink)
    : options_(std::move(options)), source_(source), sink_(sink) {}

SourceStatus CameraDriver::OpenSource(bool reconnecting) {
  const bool retry = source_->is_live() && options_.live.reconnect;
  int attempts = 0;
  while (true) {
    if (reconnecting || attempts > 0) source_->Close();
    SourceStatus st = source_->Open();
    ++attempts;
    if (st.ok()) {
      if (reconnecting) {
        ++stats_.reconnects;
        MBSLAM_LOG(INFO) << "reconnected: " << source_->description();
      }
      return st;
    }
    if (!retry || !Retryable(st.kind())) return st;
    if (options_.live.max_reconnect_attempts > 0 &&
        attempts >= options_.live.max_reconnect_attempts) {
      return SourceStatus::Error(st.kind(), st.message() + " (gave up after " +
                                                std::to_string(attempts) + " attempts)");
    }
    if (attempts == 1 || attempts % 10 == 0) {
      MBSLAM_LOG(WARNING) << st.message() << "; retrying every "
                          << options_.live.reconnect_interval_s << " s (attempt " << attempts
                          << ")";
    }
    if (!SleepUnlessShutdown(options_.live.reconnect_interval_s)) return SourceStatus::Ok();
  }
}

SourceStatus CameraDriver::ResolveCalibration(const Frame& first) {
  std::string path = options_.calibration_file;
  if (path.empty()) path = source_->dataset_calibration_file();
  CameraIntrinsics intrinsics;
  if (!path.empty()) {
    const Status st = LoadCameraIntrinsics(path, &intrinsics);
    if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
  } else {
    intrinsics = CameraIntrinsics::Approximate(first.image.cols, first.image.rows);
    intrinsics.name = "camera";
    MBSLAM_LOG(WARNING) << "no calibration file (calibration_file) for "
                        << source_->description() << ": publishing an approximate one (fx = fy = "
                        << intrinsics.fx << " px, principal point at the centre)";
  }
  if (intrinsics.width != first.image.cols || intrinsics.height != first.image.rows) {
    std::ostringstream msg;
    msg << "calibration " << (path.empty() ? "" : path + " ") << "is for " << intrinsics.width
        << "x" << intrinsics.height << " images but the frames are " << first.image.cols << "x"
        << first.image.rows;
    return SourceStatus::Error(SourceError::kConfig, msg.str());
  }
  intrinsics_ = intrinsics;
  camera_name_ = options_.camera_name.empty() ? intrinsics.name : options_.camera_name;
  if (camera_name_.empty()) camera_name_ = "camera";
  return SourceStatus::Ok();
}

void CameraDriver::CountBadFrame(const std::string& reason) {
  ++stats_.bad_frames;
  if (stats_.bad_frame_examples.size() < kMaxBadFrameExamples) {
    stats_.bad_frame_examples.push_back(reason);
  }
  if (stats_.bad_frames <= 10 || stats_.bad_frames % 100 == 0) {
    MBSLAM_LOG(WARNING) << "bad frame skipped (" << stats_.bad_frames << " so far): " << reason;
  }
}

SourceStatus CameraDriver::PublishFrame(Frame* frame) {
  const int64_t seq = next_seq_++;
  if (!intrinsics_) {
    SourceStatus st = ResolveCalibration(*frame);
    if (!st.ok()) return st;
  }
  if (frame->image.cols != intrinsics_->width || frame->image.rows != intrinsics_->height) {
    ++stats_.size_mismatches;
    std::ostringstream reason;
    reason << frame->origin << ": " << frame->image.cols << "x" << frame->image.rows
           << " instead of " << intrinsics_->width << "x" << intrinsics_->height;
    CountBadFrame(reason.str());
    return SourceStatus::Ok();
  }
  mbslam::image_t image{};
  image.utime = frame->utime;
  image.seq = seq;
  image.camera_name = camera_name_;
  const Status encoded = EncodeFrameImage(*frame, options_.image, &image);
  if (!encoded.ok()) {
    CountBadFrame(frame->origin + ": " + encoded.message());
    return SourceStatus::Ok();
  }
  const int64_t period_us = SecondsToUtime(options_.calibration_period_s);
  if (!calibration_sent_ || frame->utime - last_calibration_utime_ >= period_us ||
      frame->utime < last_calibration_utime_) {
    mbslam::camera_calibration_t calibration{};
    FillCalibrationMessage(*intrinsics_, frame->utime, camera_name_, &calibration);
    const Status st = sink_->Publish(options_.channels.camera_calibration, frame->utime, calibration);
    if (!st.ok()) return SourceStatus::Error(SourceError::kOutput, st.message());
    calibration_sent_ = true;
    last_calibration_utime_ = frame->utime;
    ++stats_.calibrations_published;
  }
  Status st = sink_->Publish(options_.channels.camera_image, frame->utime, image);
  if (!st.ok()) return SourceStatus::Error(SourceError::kOutput, st.message());
  ++stats_.frames_published;
  if (options_.ground_truth.publish && frame->has_truth_source) {
    mbslam::ground_truth_t truth{};
    FillGroundTruthMessage(*frame, seq, &truth);
    st = sink_->Publish(options_.channels.ground_truth, frame->utime, truth);
    if (!st.ok()) return SourceStatus::Error(SourceError::kOutput, st.message());
    ++stats_.truth_published;
    if (!frame->world_from_cam) ++stats_.truth_missing;
  }
  return SourceStatus::Ok();
}

SourceStatus CameraDriver::Run() {
  if (!options_.calibration_file.empty()) {
    // Check the configured calibration before touching the source.
    CameraIntrinsics intrinsics;
    const Status loaded = LoadCameraIntrinsics(options_.calibration_file, &intrinsics);
    if (!loaded.ok()) return SourceStatus::Error(SourceError::kConfig, loaded.message());
  }
  SourceStatus st = OpenSource(false);
  if (!st.ok() || ShutdownRequested()) return st;
  MBSLAM_LOG(INFO) << "source: " << source_->description() << " -> " << sink_->description();

  const bool live = source_->is_live();
  const PlaybackOptions& play = options_.playback;
  const bool paced = !live && !sink_->is_file() && play.speed > 0.0;
  PlaybackClock clock(paced ? play.speed : 0.0);
  int64_t total = source_->num_frames();
  if (total >= 0) {
    if (play.end_frame >= 0) total = std::min(total, play.end_frame);
    total = std::max<int64_t>(0, total - play.start_frame);
    if (play.loops > 1) total *= play.loops;
    if (play.loops == 0) total = -1;
  }
  ProgressBar progress(play.progress && !live);

  int64_t loop_offset = 0;
  std::optional<int64_t> first_utime;  // source time of the first frame (for start_s / end_s)
  bool stop = false;
  for (int loop = 0; !stop && (play.loops == 0 || loop < play.loops || live); ++loop) {
    if (loop > 0) {
      if (live) break;
      st = source_->Rewind();
      if (!st.ok()) return st;
    }
    if (!live && play.start_frame > 0 && !source_->SeekToIndex(play.start_frame)) {
      // The source cannot seek: the range check below drops frames before start_frame.
    }
    std::optional<int64_t> loop_first, loop_last;
    int64_t loop_frames = 0;
    while (true) {
      if (ShutdownRequested()) {
        stop = true;
        break;
      }
      Frame frame;
      SourceStatus read;
      const FrameSource::ReadResult r = source_->Next(&frame, &read);
      if (r == FrameSource::ReadResult::kEnd) break;
      if (r == FrameSource::ReadResult::kError) {
        if (live && options_.live.reconnect && Retryable(read.kind())) {
          MBSLAM_LOG(WARNING) << read.message() << "; reconnecting";
          st = OpenSource(true);
          if (!st.ok()) return st;
          if (ShutdownRequested()) {
            stop = true;
            break;
          }
          clock.Reset();
          continue;
        }
        progress.Finish();
        return read;
      }
      if (r == FrameSource::ReadResult::kBadFrame) {
        if (!live && frame.index < play.start_frame) continue;
        if (!live && play.end_frame >= 0 && frame.index >= play.end_frame) break;
        ++stats_.frames_read;
        ++next_seq_;  // a lost frame is a gap in seq
        CountBadFrame(read.message());
        progress.Update(stats_.frames_read, total, "bad " + std::to_string(stats_.bad_frames));
        continue;
      }
      if (!live) {
        if (frame.index < play.start_frame) continue;
        if (play.end_frame >= 0 && frame.index >= play.end_frame) break;
        if (!first_utime) first_utime = frame.utime;
        const int64_t rel = frame.utime - *first_utime;
        if (rel < SecondsToUtime(play.start_s)) continue;
        if (play.end_s >= 0.0 && rel > SecondsToUtime(play.end_s)) break;
        if (!loop_first) loop_first = frame.utime;
        loop_last = frame.utime;
        ++loop_frames;
        frame.utime += loop_offset;
      }
      ++stats_.frames_read;
      if (paced && !clock.WaitUntil(frame.utime)) {
        stop = true;
        break;
      }
      st = PublishFrame(&frame);
      if (!st.ok()) {
        progress.Finish();
        return st;
      }
      progress.Update(stats_.frames_read, total, "bad " + std::to_string(stats_.bad_frames));
    }
    if (!stop && !live) {
      ++stats_.loops_done;
      if (loop_first && loop_last) {
        // The next pass continues the clock: one mean frame interval after the last.
        const int64_t span = *loop_last - *loop_first;
        const int64_t period = loop_frames > 1 ? span / (loop_frames - 1)
                                               : SecondsToUtime(1.0 / options_.folder.rate_hz);
        loop_offset += span + std::max<int64_t>(1, period);
      }
    }
    if (live) break;
  }
  progress.Finish();
  sink_->Flush();
  if (!live && stats_.frames_published == 0 && !ShutdownRequested()) {
    if (stats_.bad_frames > 0) {
      return SourceStatus::Error(SourceError::kIo,
                                 "no frame of " + source_->description() + " could be used (" +
                                     std::to_string(stats_.bad_frames) + " bad; first: " +
                                     stats_.bad_frame_examples.front() + ")");
    }
    return SourceStatus::Error(SourceError::kNotFound,
                               "no frame of " + source_->description() +
                                   " lies in the requested range");
  }
  return SourceStatus::Ok();
}

std::string CameraDriver::Summary() const {
  std::ostringstream os;
  os << "published " << stats_.frames_published << " frames, " << stats_.calibrations_published
     << " calibrations";
  if (stats_.truth_published > 0) {
    os << ", " << stats_.truth_published << " ground truth (" << stats_.truth_missing
       << " without camera pose)";
  }
  os << " to " << sink_->description();
  if (stats_.loops_done > 1) os << " in " << stats_.loops_done << " loops";
  if (stats_.reconnects > 0) os << "; " << stats_.reconnects << " reconnects";
  if (stats_.bad_frames > 0) {
    os << "; " << stats_.bad_frames << " bad frames skipped (" << stats_.size_mismatches
       << " of a wrong size), first: " << stats_.bad_frame_examples.front();
  }
  return os.str();
}

}  // namespace mbslam
