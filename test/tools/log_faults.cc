#include "test/tools/log_faults.h"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include "common/lcm/wire_check.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"

namespace mbslam {
namespace fault {
namespace {

constexpr size_t kUtimeOffset = 8;  // after the type fingerprint

}  // namespace

bool ReadMessageUtime(const std::vector<uint8_t>& data, int64_t* utime) {
  if (data.size() < kUtimeOffset + 8) return false;
  uint64_t v = 0;
  for (size_t i = 0; i < 8; ++i) v = (v << 8) | data[kUtimeOffset + i];
  *utime = static_cast<int64_t>(v);
  return true;
}

void WriteMessageUtime(std::vector<uint8_t>* data, int64_t utime) {
  if (data->size() < kUtimeOffset + 8) return;
  const uint64_t v = static_cast<uint64_t>(utime);
  for (size_t i = 0; i < 8; ++i) (*data)[kUtimeOffset + i] = static_cast<uint8_t>(v >> (56 - 8 * i));
}

LogEditor::LogEditor(std::vector<LcmLogEvent> events, ChannelOptions channels)
    : events_(std::move(events)), channels_(std::move(channels)) {}

Status LogEditor::Load(const std::string& path, LogEditor* editor) {
  std::vector<LcmLogEvent> events;
  MBSLAM_RETURN_IF_ERROR(ReadLcmLog(path, &events));
  if (events.empty()) return Status::Error(path + ": no events");
  *editor = LogEditor(std::move(events), editor->channels_);
  return Status::Ok();
}

Status LogEditor::Write(const std::string& path) const {
  Status status;
  auto writer = LcmLogWriter::Open(path, &status);
  if (!writer) return status;
  for (const LcmLogEvent& e : events_) {
    MBSLAM_RETURN_IF_ERROR(writer->WriteRaw(e.channel, e.timestamp, e.data.data(), e.data.size()));
  }
  writer->Flush();
  return Status::Ok();
}

bool LogEditor::IsInput(const std::string& channel) const {
  return channel == channels_.camera_image || channel == channels_.camera_calibration ||
         channel == channels_.odometry || channel == channels_.ground_truth;
}

std::vector<size_t> LogEditor::FrameEvents() const {
  std::vector<size_t> out;
  for (size_t i = 0; i < events_.size(); ++i) {
    if (events_[i].channel == channels_.camera_image) out.push_back(i);
  }
  return out;
}

int LogEditor::num_frames() const { return static_cast<int>(FrameEvents().size()); }

int64_t LogEditor::FrameUtime(int frame) const {
  const std::vector<size_t> frames = FrameEvents();
  if (frame < 0 || frame >= static_cast<int>(frames.size())) return 0;
  int64_t utime = 0;
  return ReadMessageUtime(events_[frames[static_cast<size_t>(frame)]].data, &utime) ? utime : 0;
}

void LogEditor::Truncate(int num_frames) {
  const std::vector<size_t> frames = FrameEvents();
  if (num_frames < 0 || num_frames >= static_cast<int>(frames.size())) return;
  events_.resize(frames[static_cast<size_t>(num_frames)]);
}

int LogEditor::DropChannel(const std::string& channel) {
  const size_t before = events_.size();
  events_.erase(std::remove_if(events_.begin(), events_.end(),
                               [&](const LcmLogEvent& e) { return e.channel == channel; }),
                events_.end());
  return static_cast<int>(before - events_.size());
}

Status LogEditor::AddOdometryFromTruth(const double base_from_cam_wxyz[4], const double base_from_cam_t[3]) {
  const Eigen::Quaterniond q_bc(base_from_cam_wxyz[0], base_from_cam_wxyz[1], base_from_cam_wxyz[2],
                                base_from_cam_wxyz[3]);
  const Eigen::Vector3d t_bc(base_from_cam_t[0], base_from_cam_t[1], base_from_cam_t[2]);
  // cam_from_base = base_from_cam^-1
  const Eigen::Quaterniond q_cb = q_bc.normalized().conjugate();
  const Eigen::Vector3d t_cb = -(q_cb * t_bc);
  std::vector<LcmLogEvent> out;
  out.reserve(events_.size() * 2);
  int64_t seq = 0;
  for (LcmLogEvent& e : events_) {
    const bool truth = e.channel == channels_.ground_truth;
    mbslam::ground_truth_t gt{};
    if (truth && !DecodeLcmMessage(e.data.data(), e.data.size(), &gt).ok()) {
      return Status::Error("AddOdometryFromTruth: undecodable ground truth");
    }
    const int64_t timestamp = e.timestamp;
    out.push_back(std::move(e));
    if (!truth || !gt.has_camera) continue;
    const Eigen::Quaterniond q_wc(gt.cam_orientation[0], gt.cam_orientation[1], gt.cam_orientation[2],
                                  gt.cam_orientation[3]);
    const Eigen::Vector3d t_wc(gt.cam_position[0], gt.cam_position[1], gt.cam_position[2]);
    const Eigen::Quaterniond q_ob = (q_wc * q_cb).normalized();
    const Eigen::Vector3d t_ob = q_wc * t_cb + t_wc;
    mbslam::odometry_t o{};
    o.utime = gt.utime;
    o.seq = seq++;
    o.frame_id = "odom";
    o.child_frame_id = "base_link";
    for (int i = 0; i < 3; ++i) o.position[i] = t_ob[i];
    o.orientation[0] = q_ob.w();
    o.orientation[1] = q_ob.x();
    o.orientation[2] = q_ob.y();
    o.orientation[3] = q_ob.z();
    o.pose_covariance[0] = -1;
    o.twist_covariance[0] = -1;
    LcmLogEvent odom;
    odom.channel = channels_.odometry;
    odom.timestamp = timestamp;
    odom.data = mbslam::EncodeLcmMessage(o);
    out.push_back(std::move(odom));
  }
  events_ = std::move(out);
  return seq > 0 ? Status::Ok() : Status::Error("AddOdometryFromTruth: no ground-truth camera pose");
}

int LogEditor::DropFrames(double fraction, uint32_t seed, int first_frame, int end_frame) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<LcmLogEvent> kept;
  kept.reserve(events_.size());
  int frame = -1;
  int dropped = 0;
  for (LcmLogEvent& e : events_) {
    if (e.channel == channels_.camera_image) {
      ++frame;
      const bool candidate = frame >= first_frame && frame < end_frame;
      // One draw per frame in range, so the pattern depends only on the seed.
      if (candidate && u(rng) < fraction) {
        ++dropped;
        continue;
      }
    }
    kept.push_back(std::move(e));
  }
  events_ = std::move(kept);
  return dropped;
}

Status LogEditor::ShiftTime(int from_frame, int64_t delta_us) {
  const std::vector<size_t> frames = FrameEvents();
  if (from_frame < 0 || from_frame >= static_cast<int>(frames.size())) {
    return Status::Error("ShiftTime: no frame " + std::to_string(from_frame));
  }
  for (size_t i = frames[static_cast<size_t>(from_frame)]; i < events_.size(); ++i) {
    LcmLogEvent& e = events_[i];
    if (!IsInput(e.channel)) continue;
    int64_t utime = 0;
    if (!ReadMessageUtime(e.data, &utime)) continue;
    WriteMessageUtime(&e.data, utime + delta_us);
    e.timestamp += delta_us;
  }
  return Status::Ok();
}

int LogEditor::DropOdometry(int64_t from_utime, int64_t to_utime) {
  int dropped = 0;
  std::vector<LcmLogEvent> kept;
  kept.reserve(events_.size());
  for (LcmLogEvent& e : events_) {
    int64_t utime = 0;
    if (e.channel == channels_.odometry && ReadMessageUtime(e.data, &utime) && utime >= from_utime &&
        utime < to_utime) {
      ++dropped;
      continue;
    }
    kept.push_back(std::move(e));
  }
  events_ = std::move(kept);
  return dropped;
}

int LogEditor::CorruptOdometry(int64_t from_utime, int64_t to_utime, double value) {
  int changed = 0;
  for (LcmLogEvent& e : events_) {
    if (e.channel != channels_.odometry) continue;
    mbslam::odometry_t msg{};
    if (!DecodeLcmMessage(e.data.data(), e.data.size(), &msg).ok()) continue;
    if (msg.utime < from_utime || msg.utime >= to_utime) continue;
    switch (changed % 4) {
      case 0: msg.position[changed % 3] = value; break;
      case 1: msg.orientation[(changed + 1) % 4] = value; break;
      case 2: msg.linear_velocity[changed % 3] = value; break;
      case 3: msg.angular_velocity[changed % 3] = value; break;
    }
    e.data = mbslam::EncodeLcmMessage(msg);
    ++changed;
  }
  return changed;
}

Status LogEditor::InjectBadCalibration(int at_frame, double value) {
  const std::vector<size_t> frames = FrameEvents();
  if (at_frame < 0 || at_frame >= static_cast<int>(frames.size())) {
    return Status::Error("InjectBadCalibration: no frame " + std::to_string(at_frame));
  }
  const size_t at = frames[static_cast<size_t>(at_frame)];
  const LcmLogEvent* last = nullptr;
  for (size_t i = 0; i < at; ++i) {
    if (events_[i].channel == channels_.camera_calibration) last = &events_[i];
  }
  if (last == nullptr) return Status::Error("InjectBadCalibration: no calibration before the frame");
  mbslam::camera_calibration_t calib{};
  MBSLAM_RETURN_IF_ERROR(DecodeLcmMessage(last->data.data(), last->data.size(), &calib));
  calib.fx = value;
  calib.cy = value;
  if (calib.num_distortion > 0) calib.distortion[0] = value;
  LcmLogEvent bad;
  bad.channel = channels_.camera_calibration;
  bad.timestamp = events_[at].timestamp;
  int64_t frame_utime = 0;
  ReadMessageUtime(events_[at].data, &frame_utime);
  calib.utime = frame_utime;
  bad.data = mbslam::EncodeLcmMessage(calib);
  events_.insert(events_.begin() + static_cast<std::ptrdiff_t>(at), std::move(bad));
  return Status::Ok();
}

Status LogEditor::ResizeFrame(int frame, int width, int height) {
  const std::vector<size_t> frames = FrameEvents();
  if (frame < 0 || frame >= static_cast<int>(frames.size())) {
    return Status::Error("ResizeFrame: no frame " + std::to_string(frame));
  }
  LcmLogEvent& e = events_[frames[static_cast<size_t>(frame)]];
  mbslam::image_t img{};
  MBSLAM_RETURN_IF_ERROR(DecodeLcmMessage(e.data.data(), e.data.size(), &img));
  int type = 0;
  int channels = 0;
  switch (img.encoding) {
    case mbslam::image_t::ENCODING_GRAY8: type = CV_8UC1; channels = 1; break;
    case mbslam::image_t::ENCODING_RGB8:
    case mbslam::image_t::ENCODING_BGR8: type = CV_8UC3; channels = 3; break;
    default: return Status::Error("ResizeFrame: only raw encodings");
  }
  const cv::Mat src(img.height, img.width, type, img.data.data(), static_cast<size_t>(img.row_stride));
  cv::Mat dst;
  cv::resize(src, dst, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  img.width = width;
  img.height = height;
  img.row_stride = width * channels;
  img.data.assign(dst.data, dst.data + dst.total() * dst.elemSize());
  img.size = static_cast<int32_t>(img.data.size());
  e.data = mbslam::EncodeLcmMessage(img);
  return Status::Ok();
}

Status LogEditor::Burst(int first_frame, int count, double factor) {
  const std::vector<size_t> frames = FrameEvents();
  const int end = first_frame + count;
  if (first_frame < 1 || count < 2 || end > static_cast<int>(frames.size()) || factor <= 1.0) {
    return Status::Error("Burst: bad window");
  }
  const size_t begin_event = frames[static_cast<size_t>(first_frame)];
  const size_t last_event = frames[static_cast<size_t>(end - 1)];
  const int64_t t_first = events_[begin_event].timestamp;
  const int64_t t_last = events_[last_event].timestamp;
  const double period = static_cast<double>(t_last - t_first) / (count - 1);
  // New delivery time of frame first_frame + j: t_last - (count - 1 - j) * period / factor;
  // the messages between two frames follow their frame.
  int j = -1;
  for (size_t i = begin_event; i <= last_event; ++i) {
    if (events_[i].channel == channels_.camera_image) ++j;
    const double back = (count - 1 - j) * period / factor;
    events_[i].timestamp = std::max<int64_t>(t_first, t_last - static_cast<int64_t>(std::llround(back)));
  }
  return Status::Ok();
}

}  // namespace fault
}  // namespace mbslam
