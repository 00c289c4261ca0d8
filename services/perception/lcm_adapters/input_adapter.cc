#include "services/perception/lcm_adapters/input_adapter.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/lcm/wire_check.h"
#include "common/util/logging.h"
#include "common/util/time.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "mbslam/snapshot_request_t.hpp"
#include "services/perception/pipeline/image_decode.h"

namespace mbslam {
namespace {

// a - b, saturated instead of overflowing: times and sequence numbers come from the
// wire and can be anything (INT64_MAX after a negative time overflowed a - b).
int64_t SaturatingSub(int64_t a, int64_t b) {
  int64_t d = 0;
  if (__builtin_sub_overflow(a, b, &d)) {
    return a > b ? std::numeric_limits<int64_t>::max() : std::numeric_limits<int64_t>::min();
  }
  return d;
}

}  // namespace

std::unique_ptr<InputAdapter> InputAdapter::Create(const InputOptions& options,
                                                   const PipelineOptions& pipeline_options,
                                                   PerceptionPipeline* pipeline,
                                                   Counters* counters, Status* status) {
  std::unique_ptr<InputAdapter> adapter(
      new InputAdapter(options, pipeline_options, pipeline, counters));
  if (!options.calibration_file.empty()) {
    CameraIntrinsics intrinsics;
    *status = LoadCameraIntrinsics(options.calibration_file, &intrinsics);
    if (!status->ok()) return nullptr;
    adapter->intrinsics_ = std::make_shared<const CameraIntrinsics>(intrinsics);
  }
  *status = Status::Ok();
  return adapter;
}

InputAdapter::InputAdapter(const InputOptions& options, const PipelineOptions& pipeline_options,
                           PerceptionPipeline* pipeline, Counters* counters)
    : options_(options),
      max_image_dimension_(pipeline_options.max_image_dimension),
      max_frame_gap_us_(pipeline_options.max_frame_gap_us),
      pipeline_(pipeline),
      counters_(counters) {}

void InputAdapter::Subscribe(LcmBus* bus, const ChannelOptions& channels) {
  const int q = options_.subscription_queue;
  bus->Subscribe(channels.camera_image,
                 [this](const std::string&, const uint8_t* d, size_t n, int64_t) {
                   HandleImage(d, n, WallUtime());
                 }, q);
  bus->Subscribe(channels.camera_calibration,
                 [this](const std::string&, const uint8_t* d, size_t n, int64_t) {
                   HandleCalibration(d, n);
                 }, q);
  bus->Subscribe(channels.odometry,
                 [this](const std::string&, const uint8_t* d, size_t n, int64_t) {
                   HandleOdometry(d, n);
                 }, 10 * q);
  bus->Subscribe(channels.snapshot_request,
                 [this](const std::string&, const uint8_t* d, size_t n, int64_t) {
                   HandleSnapshotRequest(d, n);
                 }, q);
}

void InputAdapter::Reject(const char* counter_name, const std::string& why) {
  counters_->Increment(counter_name);
  pipeline_->CountRejected();
  MBSLAM_LOG(DEBUG) << "image rejected (" << counter_name << "): " << why;
}

void InputAdapter::HandleImage(const uint8_t* data, size_t size, int64_t wall_utime) {
  mbslam::image_t msg{};
  const Status decoded =
      DecodeLcmMessage(data, size, &msg, static_cast<size_t>(options_.max_message_bytes));
  if (!decoded.ok()) return Reject(counter::kImageDecodeError, decoded.message());

  RawImage raw;
  switch (msg.encoding) {
    case mbslam::image_t::ENCODING_GRAY8: raw.encoding = ImageEncoding::kGray8; break;
    case mbslam::image_t::ENCODING_RGB8: raw.encoding = ImageEncoding::kRgb8; break;
    case mbslam::image_t::ENCODING_BGR8: raw.encoding = ImageEncoding::kBgr8; break;
    case mbslam::image_t::ENCODING_JPEG: raw.encoding = ImageEncoding::kJpeg; break;
    case mbslam::image_t::ENCODING_PNG: raw.encoding = ImageEncoding::kPng; break;
    default:
      return Reject(counter::kImageUnknownEncoding, "encoding " + std::to_string(msg.encoding));
  }
  raw.utime = msg.utime;
  raw.seq = msg.seq;
  raw.receive_wall_utime = wall_utime;
  raw.width = msg.width;
  raw.height = msg.height;
  raw.row_stride = msg.row_stride;
  raw.bytes = std::move(msg.data);
  if (raw.width <= 0 || raw.height <= 0 || raw.width > max_image_dimension_ ||
      raw.height > max_image_dimension_) {
    return Reject(counter::kImageBadSize,
                  std::to_string(raw.width) + "x" + std::to_string(raw.height));
  }
  const Status valid = ValidateRawImage(raw, max_image_dimension_);
  if (!valid.ok()) return Reject(counter::kImageSizeMismatch, valid.message());

  // Time must increase. A lasting step back (replay loop, clock reset) starts a new
  // timeline after time_reset_after_frames frames instead of rejecting forever.
  if (last_image_utime_ != 0 && raw.utime <= last_image_utime_) {
    ++backwards_streak_;
    if (backwards_streak_ < options_.time_reset_after_frames) {
      return Reject(counter::kImageTimeBackwards,
                    std::to_string(raw.utime) + " <= " + std::to_string(last_image_utime_));
    }
    counters_->Increment(counter::kImageTimelineReset);
    raw.timeline_reset = true;
    last_odometry_utime_ = 0;
  } else if (last_image_utime_ != 0 && backwards_streak_ == 0 && last_seq_ >= 0 &&
             SaturatingSub(raw.seq, last_seq_) > 1) {
    counters_->Increment(counter::kImageSeqGap, SaturatingSub(raw.seq, last_seq_) - 1);
  }
  backwards_streak_ = 0;
  if (last_image_utime_ != 0 && !raw.timeline_reset &&
      SaturatingSub(raw.utime, last_image_utime_) > max_frame_gap_us_) {
    // Reported; the tracker decides what a gap means for it.
    counters_->Increment(counter::kImageTimeJump);
  }
  if (raw.seq < last_seq_ && !raw.timeline_reset) counters_->Increment(counter::kImageSeqRestart);

  std::shared_ptr<const CameraIntrinsics> intrinsics = intrinsics_;
  if (intrinsics && (intrinsics->width != raw.width || intrinsics->height != raw.height)) {
    return Reject(counter::kImageCalibrationMismatch,
                  "calibration is " + std::to_string(intrinsics->width) + "x" +
                      std::to_string(intrinsics->height));
  }
  // Another size than the images before: tracks and map cannot continue across it. A
  // stray frame is dropped; a lasting change (the calibration says so, or
  // time_reset_after_frames images in a row) starts a new timeline.
  if (last_width_ > 0 && (raw.width != last_width_ || raw.height != last_height_)) {
    const std::string why = std::to_string(raw.width) + "x" + std::to_string(raw.height) + " after " +
                            std::to_string(last_width_) + "x" + std::to_string(last_height_);
    if (!intrinsics && ++size_change_streak_ < options_.time_reset_after_frames) {
      return Reject(counter::kImageSizeChanged, why);
    }
    counters_->Increment(counter::kImageSizeChanged);
    MBSLAM_LOG(WARNING) << "image size changed (" << why << "): starting over";
    if (!raw.timeline_reset) {
      counters_->Increment(counter::kImageTimelineReset);
      raw.timeline_reset = true;
    }
  }
  size_change_streak_ = 0;
  if (!intrinsics) {
    if (options_.fallback_focal_factor <= 0.0) {
      return Reject(counter::kImageUncalibrated, "no calibration and no fallback");
    }
    if (!fallback_ || fallback_->width != raw.width || fallback_->height != raw.height) {
      fallback_ = std::make_shared<const CameraIntrinsics>(
          CameraIntrinsics::Approximate(raw.width, raw.height, options_.fallback_focal_factor));
      MBSLAM_LOG(WARNING) << "no camera calibration: using approximate intrinsics f = "
                          << fallback_->fx << " px";
    }
    counters_->Increment(counter::kImageUncalibrated);
    intrinsics = fallback_;
  }
  raw.intrinsics = std::move(intrinsics);
  // Odometry that stopped is reported per image until it is back.
  if (raw.timeline_reset) {
    if (odometry_clock_utime_ != 0) odometry_clock_utime_ = raw.utime;
  } else if (odometry_clock_utime_ != 0 && raw.utime > odometry_clock_utime_ &&
             static_cast<uint64_t>(raw.utime) - static_cast<uint64_t>(odometry_clock_utime_) >
                 static_cast<uint64_t>(options_.odometry_timeout_us)) {
    counters_->Increment(counter::kImageWithoutOdometry);
    if (!odometry_stale_) {
      MBSLAM_LOG(WARNING) << "no odometry since " << odometry_clock_utime_ << " (image " << raw.utime
                          << "): images go on without it";
    }
    odometry_stale_ = true;
  }
  last_image_utime_ = raw.utime;
  last_seq_ = raw.seq;
  last_width_ = raw.width;
  last_height_ = raw.height;
  pipeline_->Push(InputEvent(std::move(raw)));
}

void InputAdapter::HandleCalibration(const uint8_t* data, size_t size) {
  if (!options_.use_calibration_messages) return;
  mbslam::camera_calibration_t msg{};
  const Status decoded = DecodeLcmMessage(data, size, &msg, 1 << 20);
  if (!decoded.ok()) {
    counters_->Increment(counter::kCalibrationDecodeError);
    return;
  }
  CameraIntrinsics c;
  c.name = msg.camera_name;
  c.width = msg.width;
  c.height = msg.height;
  c.fx = msg.fx;
  c.fy = msg.fy;
  c.cx = msg.cx;
  c.cy = msg.cy;
  switch (msg.distortion_model) {
    case mbslam::camera_calibration_t::DISTORTION_NONE: c.model = DistortionModel::kNone; break;
    case mbslam::camera_calibration_t::DISTORTION_RADTAN: c.model = DistortionModel::kRadTan; break;
    case mbslam::camera_calibration_t::DISTORTION_FISHEYE: c.model = DistortionModel::kFisheye; break;
    default:
      counters_->Increment(counter::kCalibrationInvalid);
      return;
  }
  c.distortion = msg.distortion;
  const Status valid = c.Validate();
  if (!valid.ok()) {
    counters_->Increment(counter::kCalibrationInvalid);
    MBSLAM_LOG(WARNING) << "CAMERA_CALIBRATION rejected: " << valid.message();
    return;
  }
  if (intrinsics_ && intrinsics_->width == c.width && intrinsics_->height == c.height &&
      intrinsics_->fx == c.fx && intrinsics_->fy == c.fy && intrinsics_->cx == c.cx &&
      intrinsics_->cy == c.cy && intrinsics_->model == c.model &&
      intrinsics_->distortion == c.distortion) {
    return;  // unchanged (drivers repeat it periodically)
  }
  MBSLAM_LOG(INFO) << "camera calibration: " << c.width << "x" << c.height << " f = " << c.fx
                   << ", " << c.fy << " c = " << c.cx << ", " << c.cy << " distortion "
                   << DistortionModelName(c.model);
  intrinsics_ = std::make_shared<const CameraIntrinsics>(c);
}

void InputAdapter::HandleOdometry(const uint8_t* data, size_t size) {
  mbslam::odometry_t msg{};
  const Status decoded = DecodeLcmMessage(data, size, &msg, 1 << 20);
  if (!decoded.ok()) {
    counters_->Increment(counter::kOdometryDecodeError);
    return;
  }
  OdometrySample s;
  s.utime = msg.utime;
  const Eigen::Quaterniond q(msg.orientation[0], msg.orientation[1], msg.orientation[2],
                             msg.orientation[3]);
  const Eigen::Vector3d t(msg.position[0], msg.position[1], msg.position[2]);
  bool finite = q.coeffs().allFinite() && t.allFinite();
  for (int i = 0; i < 3; ++i) {
    finite = finite && std::isfinite(msg.linear_velocity[i]) && std::isfinite(msg.angular_velocity[i]);
  }
  if (!finite || std::abs(q.norm() - 1.0) > 1e-3) {
    counters_->Increment(counter::kOdometryInvalid);
    return;
  }
  if (last_odometry_utime_ != 0 && s.utime <= last_odometry_utime_) {
    counters_->Increment(counter::kOdometryTimeBackwards);
    return;
  }
  if (odometry_stale_ ||
      (last_odometry_utime_ != 0 && static_cast<uint64_t>(s.utime) - static_cast<uint64_t>(last_odometry_utime_) >
                                        static_cast<uint64_t>(options_.odometry_timeout_us))) {
    counters_->Increment(counter::kOdometryGap);
    MBSLAM_LOG(WARNING) << "odometry back at " << s.utime << " after a gap since "
                        << std::max(last_odometry_utime_, odometry_clock_utime_);
  }
  odometry_stale_ = false;
  odometry_clock_utime_ = s.utime;
  last_odometry_utime_ = s.utime;
  s.odom_from_base = Rigid3d(q, t);
  for (int i = 0; i < 3; ++i) {
    s.twist_in_base[i] = msg.linear_velocity[i];
    s.twist_in_base[3 + i] = msg.angular_velocity[i];
  }
  if (msg.pose_covariance[0] >= 0.0) {
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        const double v = msg.pose_covariance[r * 6 + c];
        s.pose_covariance(r, c) = std::isfinite(v) ? v : 0.0;
      }
    }
  }
  pipeline_->Push(InputEvent(std::move(s)));
}

void InputAdapter::HandleSnapshotRequest(const uint8_t* data, size_t size) {
  mbslam::snapshot_request_t msg{};
  if (!DecodeLcmMessage(data, size, &msg, 1 << 16).ok()) {
    counters_->Increment(counter::kSnapshotDecodeError);
    return;
  }
  if (snapshot_callback_) snapshot_callback_(msg.path_prefix, msg.what);
}

}  // namespace mbslam
