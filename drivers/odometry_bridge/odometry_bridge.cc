#include "drivers/odometry_bridge/odometry_bridge.h"

#include <climits>
#include <sstream>

#include "common/lcm/wire_check.h"
#include "common/util/logging.h"
#include "common/util/shutdown.h"
#include "common/util/time.h"
#include "drivers/common/exit_codes.h"
#include "drivers/common/playback.h"
#include "drivers/odometry_bridge/dds_odometry.h"
#include "drivers/odometry_bridge/odometry_files.h"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "mbslam/pose_t.hpp"

namespace mbslam {
namespace {

void PutPose(const Rigid3d& pose, double position[3], double orientation[4]) {
  for (int i = 0; i < 3; ++i) position[i] = pose.translation[i];
  orientation[0] = pose.rotation.w();
  orientation[1] = pose.rotation.x();
  orientation[2] = pose.rotation.y();
  orientation[3] = pose.rotation.z();
}

}  // namespace

OdometryBridge::OdometryBridge(OdometryBridgeOptions options, MessageSink* sink, LcmBus* bus)
    : options_(std::move(options)), sink_(sink), bus_(bus) {}

OdometryBridge::~OdometryBridge() = default;

Status OdometryBridge::Fail(int code, const std::string& message) {
  exit_code_ = code;
  return Status::Error(message);
}

Status OdometryBridge::HandleSample(OdometrySample sample) {
  ++stats_.received;
  const Status valid = ValidateOdometrySample(sample);
  if (!valid.ok()) {
    ++stats_.rejected;
    if (stats_.rejected <= 10) MBSLAM_LOG(WARNING) << "odometry rejected: " << valid.message();
    return Status::Ok();
  }
  if (sample.utime <= last_utime_) {
    ++stats_.out_of_order;
    if (stats_.out_of_order <= 10) {
      MBSLAM_LOG(WARNING) << "odometry at " << sample.utime << " us is not newer than the previous ("
                          << last_utime_ << " us); dropped";
    }
    return Status::Ok();
  }
  last_utime_ = sample.utime;
  mbslam::odometry_t msg{};
  ToOdometryMessage(sample, &msg);
  const Status st = sink_->Publish(options_.channels.odometry, sample.utime, msg);
  if (!st.ok()) return Fail(kExitOutputError, st.message());
  ++stats_.published;
  if (sync_) {
    std::vector<ImageOdometry> results;
    sync_->AddOdometry(sample, &results);
    MBSLAM_RETURN_IF_ERROR(PublishSynced(results));
  }
  return Status::Ok();
}

Status OdometryBridge::PublishSynced(const std::vector<ImageOdometry>& results) {
  for (const ImageOdometry& r : results) {
    if (r.result != InterpolationResult::kOk) {
      ++reported_outside_;
      if (reported_outside_ <= 10 || reported_outside_ % 100 == 0) {
        MBSLAM_LOG(WARNING) << "image " << r.image.seq << " at " << r.image.utime
                            << " us has no camera pose: " << InterpolationResultName(r.result)
                            << " (" << r.detail << ")";
      }
      continue;
    }
    mbslam::pose_t pose{};
    pose.utime = r.image.utime;
    pose.target_frame = r.frame_id;
    pose.source_frame = r.image.camera_name.empty() ? "cam" : r.image.camera_name;
    PutPose(r.odom_from_cam, pose.position, pose.orientation);
    const Status st = sink_->Publish(options_.image_sync.output_channel, pose.utime, pose);
    if (!st.ok()) return Fail(kExitOutputError, st.message());
    ++stats_.camera_poses;
  }
  return Status::Ok();
}

Status OdometryBridge::HandleImages() {
  while (!images_.empty()) {
    std::vector<ImageOdometry> results;
    sync_->AddImage(images_.front(), &results);
    images_.pop_front();
    MBSLAM_RETURN_IF_ERROR(PublishSynced(results));
  }
  return Status::Ok();
}

Status OdometryBridge::Run() {
  exit_code_ = kExitOk;
  if (!options_.Check()) return Fail(kExitUsage, "options: " + LastOptionError());
  if (options_.image_sync.enabled) {
    if (bus_ == nullptr) return Fail(kExitUsage, "image_sync needs an LCM bus for the images");
    Rigid3d base_from_cam;
    const Status st = options_.base_from_cam.Resolve(&base_from_cam);
    if (!st.ok()) return Fail(kExitUsage, st.message());
    sync_ = std::make_unique<ImageOdometrySync>(
        base_from_cam, SecondsToUtime(options_.image_sync.max_gap_s),
        SecondsToUtime(options_.image_sync.max_wait_s),
        static_cast<size_t>(options_.image_sync.max_pending_images));
    bus_->Subscribe(
        options_.channels.camera_image,
        [this](const std::string&, const uint8_t* data, size_t size, int64_t) {
          mbslam::image_t image{};
          if (!DecodeLcmMessage(data, size, &image).ok()) return;
          images_.push_back(ImageStamp{image.utime, image.seq, image.camera_name});
        },
        1000);
  }

  // The input.
  std::vector<OdometrySample> file_samples;
  std::unique_ptr<DdsOdometryReader> dds_reader;
  const std::string& input = options_.input;
  if (input == "csv" || input == "tum") {
    if (options_.file.empty()) return Fail(kExitUsage, "input '" + input + "' needs a file (--file)");
    std::FILE* probe = std::fopen(options_.file.c_str(), "r");
    if (probe == nullptr) return Fail(kExitInputNotFound, "cannot open odometry file " + options_.file);
    std::fclose(probe);
    const Status st = input == "csv" ? ReadOdometryCsv(options_.file, &file_samples)
                                     : ReadOdometryTum(options_.file, options_.derive_twist, &file_samples);
    if (!st.ok()) return Fail(kExitUsage, st.message());
    input_description_ = input + " file " + options_.file;
  } else if (input == "dds") {
    Status st;
    dds_reader = DdsOdometryReader::Create(options_.dds, &st);
    if (!dds_reader) return Fail(kExitRuntimeError, st.message());
    input_description_ = dds_reader->description();
  } else {
    if (bus_ == nullptr) return Fail(kExitUsage, "input 'lcm' needs an LCM bus");
    bus_->Subscribe(
        options_.pose_channel,
        [this](const std::string&, const uint8_t* data, size_t size, int64_t) {
          OdometrySample s;
          const Status st = OdometryFromPoseMessage(
              data, size, previous_lcm_pose_ ? &*previous_lcm_pose_ : nullptr,
              options_.derive_twist, &s);
          if (!st.ok()) {
            ++stats_.received;
            ++stats_.rejected;
            return;
          }
          previous_lcm_pose_ = s;
          lcm_samples_.push_back(s);
        },
        1000);
    input_description_ = "pose_t on " + options_.pose_channel + " (" + bus_->url() + ")";
  }
  MBSLAM_LOG(INFO) << "odometry from " << input_description_ << " -> " << sink_->description();

  const bool file_input = !file_samples.empty();
  PlaybackClock clock(file_input && !sink_->is_file() ? options_.speed : 0.0);
  size_t next_file_sample = 0;
  int64_t last_activity = MonotonicUtime();
  const int64_t idle_us = SecondsToUtime(options_.idle_timeout_s);
  while (!ShutdownRequested()) {
    bool got = false;
    OdometrySample sample;
    if (file_input) {
      if (next_file_sample >= file_samples.size()) break;
      sample = file_samples[next_file_sample++];
      if (!clock.WaitUntil(sample.utime)) break;
      got = true;
    } else if (dds_reader) {
      got = dds_reader->Pop(&sample, 50000);
    } else if (lcm_samples_.empty()) {
      bus_->HandleTimeout(50);
    }
    if (!got && !lcm_samples_.empty()) {
      sample = lcm_samples_.front();
      lcm_samples_.pop_front();
      got = true;
    }
    if (bus_ != nullptr && input != "lcm") {
      while (bus_->HandleTimeout(0) > 0) {
      }
    }
    if (got) {
      last_activity = MonotonicUtime();
      MBSLAM_RETURN_IF_ERROR(HandleSample(sample));
    }
    if (sync_) MBSLAM_RETURN_IF_ERROR(HandleImages());
    if (options_.max_messages > 0 && stats_.published >= options_.max_messages) break;
    if (!file_input && idle_us > 0 && MonotonicUtime() - last_activity > idle_us) {
      if (stats_.received == 0) {
        std::ostringstream msg;
        msg << "no odometry from " << input_description_ << " within " << options_.idle_timeout_s << " s";
        if (dds_reader) msg << " (" << dds_reader->matched_writers() << " publishers matched)";
        return Fail(kExitInputTimeout, msg.str());
      }
      break;
    }
  }
  if (dds_reader) {
    stats_.rejected += dds_reader->rejected();
    stats_.received += dds_reader->rejected();
    if (dds_reader->dropped() > 0) {
      MBSLAM_LOG(WARNING) << dds_reader->dropped() << " DDS samples dropped (queue full)";
    }
    if (dds_reader->rejected() > 0) {
      MBSLAM_LOG(WARNING) << dds_reader->rejected() << " DDS samples rejected, last: "
                          << dds_reader->last_rejection();
    }
  }
  if (sync_) {
    std::vector<ImageOdometry> results;
    sync_->Flush(&results);
    MBSLAM_RETURN_IF_ERROR(PublishSynced(results));
  }
  sink_->Flush();
  return Status::Ok();
}

std::string OdometryBridge::Summary() const {
  std::ostringstream os;
  os << "published " << stats_.published << " odometry messages from " << stats_.received << " received";
  if (stats_.rejected > 0) os << " (" << stats_.rejected << " rejected)";
  if (stats_.out_of_order > 0) os << " (" << stats_.out_of_order << " out of order)";
  if (sync_) {
    const ImageSyncStats& s = sync_->stats();
    os << "; images: " << s.images << ", camera poses " << stats_.camera_poses << ", before the first odometry "
       << s.before_first << ", after the last " << s.after_last << ", in a gap " << s.in_gap;
  }
  os << " -> " << sink_->description();
  return os.str();
}

}  // namespace mbslam
