#include "tools/sim/sequence_writer.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <thread>

#include "common/config/options_yaml.h"
#include "common/lcm/lcm_log.h"
#include "common/util/atomic_file.h"
#include "common/util/bounded_queue.h"
#include "common/util/logging.h"
#include "common/util/time.h"
#include "mbslam/camera_calibration_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/image_t.hpp"
#include "mbslam/odometry_t.hpp"
#include "tools/eval/trajectory.h"
#include "tools/sim/scenarios.h"

namespace mbslam {
namespace sim {
namespace {

namespace fs = std::filesystem;

std::string FrameName(int k, const char* ext) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%06d.%s", k, ext);
  return buf;
}

void CopyPose(const Rigid3d& pose, double position[3], double orientation[4]) {
  for (int i = 0; i < 3; ++i) {
    position[i] = pose.translation[i];
  }
  orientation[0] = pose.rotation.w();
  orientation[1] = pose.rotation.x();
  orientation[2] = pose.rotation.y();
  orientation[3] = pose.rotation.z();
}

void CopyVector(const Eigen::Vector3d& v, double out[3]) {
  for (int i = 0; i < 3; ++i) {
    out[i] = v[i];
  }
}

void CopyMatrix(const Matrix6d& m, double out[36]) {
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) {
      out[r * 6 + c] = m(r, c);  // row-major
    }
  }
}

Status MakeImageMessage(const SimFrame& frame, const Simulator& sim, const SequenceWriterOptions& o,
                        mbslam::image_t* msg) {
  msg->utime = frame.utime;
  msg->seq = frame.index;
  msg->camera_name = sim.intrinsics().name;
  msg->width = sim.intrinsics().width;
  msg->height = sim.intrinsics().height;
  const cv::Mat& gray = frame.image_gray;
  const cv::Mat& bgr = frame.image_bgr;
  if (o.lcm_image_encoding == "gray8") {
    msg->encoding = mbslam::image_t::ENCODING_GRAY8;
    msg->row_stride = gray.cols;
    msg->data.assign(gray.data, gray.data + gray.total());
  } else if (o.lcm_image_encoding == "bgr8") {
    msg->encoding = mbslam::image_t::ENCODING_BGR8;
    msg->row_stride = bgr.cols * 3;
    msg->data.assign(bgr.data, bgr.data + bgr.total() * 3);
  } else {
    const bool png = o.lcm_image_encoding == "png";
    std::vector<int> params;
    if (!png) {
      params = {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality};
    }
    std::vector<uint8_t> bytes;
    if (!cv::imencode(png ? ".png" : ".jpg", o.color_images ? bgr : gray, bytes, params)) {
      return Status::Error("encoding image " + std::to_string(frame.index) + " failed");
    }
    msg->encoding = png ? mbslam::image_t::ENCODING_PNG : mbslam::image_t::ENCODING_JPEG;
    msg->row_stride = 0;
    msg->data = std::move(bytes);
  }
  msg->size = static_cast<int32_t>(msg->data.size());
  return Status::Ok();
}

mbslam::camera_calibration_t MakeCalibrationMessage(int64_t utime, const CameraIntrinsics& K) {
  mbslam::camera_calibration_t msg{};
  msg.utime = utime;
  msg.camera_name = K.name;
  msg.width = K.width;
  msg.height = K.height;
  msg.fx = K.fx;
  msg.fy = K.fy;
  msg.cx = K.cx;
  msg.cy = K.cy;
  msg.distortion_model = mbslam::camera_calibration_t::DISTORTION_NONE;
  msg.num_distortion = 0;
  return msg;
}

mbslam::ground_truth_t MakeGroundTruthMessage(const SimFrame& frame, const std::string& scenario) {
  mbslam::ground_truth_t msg{};
  msg.utime = frame.utime;
  msg.frame_seq = frame.index;
  msg.source = "sim:" + scenario;
  msg.has_camera = 1;
  CopyPose(frame.world_from_cam, msg.cam_position, msg.cam_orientation);
  for (const auto& b : frame.bodies) {
    mbslam::body_state_t s{};
    s.id = b.id;
    s.name = b.name;
    CopyPose(b.world_from_body, s.position, s.orientation);
    CopyVector(b.linear_velocity, s.linear_velocity);
    CopyVector(b.angular_velocity, s.angular_velocity);
    CopyVector(b.extent, s.extent);
    s.visible = b.visible ? 1 : 0;
    msg.bodies.push_back(s);
  }
  msg.num_bodies = static_cast<int32_t>(msg.bodies.size());
  return msg;
}

mbslam::odometry_t MakeOdometryMessage(const OdometrySample& o) {
  mbslam::odometry_t msg{};
  msg.utime = o.utime;
  msg.seq = o.seq;
  msg.frame_id = "odom";
  msg.child_frame_id = "base_link";
  CopyPose(o.odom_from_base, msg.position, msg.orientation);
  CopyMatrix(o.pose_covariance, msg.pose_covariance);
  CopyVector(o.linear_velocity, msg.linear_velocity);
  CopyVector(o.angular_velocity, msg.angular_velocity);
  CopyMatrix(o.twist_covariance, msg.twist_covariance);
  return msg;
}

Status WriteImage(const std::string& path, const cv::Mat& img,
                  const std::vector<int>& params = {}) {
  try {
    if (!cv::imwrite(path, img, params)) {
      return Status::Error("cannot write " + path);
    }
  } catch (const cv::Exception& e) {
    return Status::Error("cannot write " + path + ": " + e.what());
  }
  return Status::Ok();
}

std::string Vec3Yaml(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out.precision(12);
  out << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

// Writes images/, masks/, depth/ of frame k.
Status WriteFrameFiles(const fs::path& root, const SequenceWriterOptions& options, int k,
                       const cv::Mat& image, const cv::Mat& mask, const cv::Mat& depth) {
  MBSLAM_RETURN_IF_ERROR(WriteImage((root / "images" / FrameName(k, "png")).string(), image));
  if (options.write_masks) {
    MBSLAM_RETURN_IF_ERROR(WriteImage((root / "masks" / FrameName(k, "png")).string(), mask));
  }
  if (!options.write_depth) {
    return Status::Ok();
  }
  if (options.depth_format == "exr") {
    const int compression = options.exr_compression == "none"  ? cv::IMWRITE_EXR_COMPRESSION_NO
                            : options.exr_compression == "zip" ? cv::IMWRITE_EXR_COMPRESSION_ZIP
                                                               : cv::IMWRITE_EXR_COMPRESSION_RLE;
    return WriteImage((root / "depth" / FrameName(k, "exr")).string(), depth,
                      {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT,
                       cv::IMWRITE_EXR_COMPRESSION, compression});
  }
  cv::Mat mm(depth.size(), CV_16UC1);
  for (int r = 0; r < mm.rows; ++r) {
    const float* d = depth.ptr<float>(r);
    uint16_t* out = mm.ptr<uint16_t>(r);
    for (int c = 0; c < mm.cols; ++c) {
      const double v = std::round(d[c] * 1000.0);
      out[c] = (v > 0.0 && v <= 65535.0) ? static_cast<uint16_t>(v) : 0;
    }
  }
  return WriteImage((root / "depth" / FrameName(k, "png")).string(), mm);
}

// Writes frame files on a thread of its own while the next frame renders. Joined by
// Finish() or the destructor.
class FileWriterThread {
 public:
  FileWriterThread(fs::path root, const SequenceWriterOptions& options)
      : root_(std::move(root)),
        options_(options),
        queue_(4, QueueFullPolicy::kBlock),
        thread_([this] { Run(); }) {}
  ~FileWriterThread() { Finish(); }

  bool Push(int k, cv::Mat image, cv::Mat mask, cv::Mat depth) {
    return queue_.Push(Job{k, std::move(image), std::move(mask), std::move(depth)});
  }
  // Waits for every queued frame; the first error, if any.
  Status Finish() {
    queue_.Shutdown();
    if (thread_.joinable()) {
      thread_.join();
    }
    return status_;
  }

 private:
  struct Job {
    int k;
    cv::Mat image, mask, depth;
  };
  void Run() {
    while (auto job = queue_.Pop()) {
      if (!status_.ok()) {
        continue;  // drain after an error
      }
      status_ = WriteFrameFiles(root_, options_, job->k, job->image, job->mask, job->depth);
    }
  }

  const fs::path root_;
  const SequenceWriterOptions options_;
  BoundedQueue<Job> queue_;
  Status status_;  // written by the thread only, read after join
  std::thread thread_;
};

Status MakeDirs(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) {
    return Status::Error("cannot create " + dir + ": " + ec.message());
  }
  return Status::Ok();
}

}  // namespace

Status WriteSequence(Simulator* sim, const std::string& dir, const SequenceWriterOptions& options,
                     SequenceSummary* summary, const std::function<void(int)>& progress) {
  if (!options.Check()) {
    return Status::Error("sequence writer options: " + LastOptionError());
  }
  const int64_t t_start = MonotonicUtime();
  *summary = SequenceSummary();
  MBSLAM_RETURN_IF_ERROR(MakeDirs(dir));
  const fs::path root(dir);
  if (options.write_files) {
    MBSLAM_RETURN_IF_ERROR(MakeDirs((root / "images").string()));
    if (options.write_masks) {
      MBSLAM_RETURN_IF_ERROR(MakeDirs((root / "masks").string()));
    }
    if (options.write_depth) {
      MBSLAM_RETURN_IF_ERROR(MakeDirs((root / "depth").string()));
    }
  }
  std::unique_ptr<LcmLogWriter> log;
  if (options.write_lcm) {
    Status st;
    log = LcmLogWriter::Open((root / "sequence.lcmlog").string(), &st);
    if (!log) {
      return st;
    }
  }

  std::unique_ptr<FileWriterThread> files;
  if (options.write_files) {
    files = std::make_unique<FileWriterThread>(root, options);
  }
  const std::vector<int> ids = sim->MovingBodyIds();
  summary->frames_visible.assign(ids.size(), 0);
  eval::Trajectory cam_traj;
  std::vector<eval::Trajectory> object_traj(ids.size());
  std::string timestamps;
  const auto& odometry = sim->odometry();
  size_t next_odometry = 0;
  int64_t last_calibration = 0;
  const int64_t calibration_period = SecondsToUtime(options.calibration_period_s);
  double fraction_sum = 0.0;
  summary->min_moving_fraction = 1.0;
  SimFrame frame;
  for (int k = 0; k < sim->num_frames(); ++k) {
    const int64_t t_render = MonotonicUtime();
    MBSLAM_RETURN_IF_ERROR(sim->RenderFrame(k, &frame));
    summary->render_seconds += 1e-6 * static_cast<double>(MonotonicUtime() - t_render);
    const double fraction = frame.MovingFraction();
    fraction_sum += fraction;
    summary->min_moving_fraction = std::min(summary->min_moving_fraction, fraction);
    summary->max_moving_fraction = std::max(summary->max_moving_fraction, fraction);
    for (size_t i = 0; i < frame.bodies.size(); ++i) {
      if (frame.bodies[i].visible) {
        ++summary->frames_visible[i];
      }
      object_traj[i].push_back({frame.utime, frame.bodies[i].world_from_body});
    }
    cam_traj.push_back({frame.utime, frame.world_from_cam});
    timestamps += std::to_string(k) + " " + std::to_string(frame.utime) + "\n";

    if (files) {
      // The writer thread shares the frame's buffers; RenderFrame allocates new ones for
      // the next frame, so nothing is written into them again.
      if (!files->Push(k, options.color_images ? frame.image_bgr : frame.image_gray, frame.mask,
                       frame.depth)) {
        return files->Finish();
      }
    }
    if (log) {
      while (next_odometry < odometry.size() && odometry[next_odometry].utime <= frame.utime) {
        const auto& o = odometry[next_odometry++];
        MBSLAM_RETURN_IF_ERROR(
            log->Write(options.channels.odometry, o.utime, MakeOdometryMessage(o)));
      }
      if (k == 0 || frame.utime - last_calibration >= calibration_period) {
        last_calibration = frame.utime;
        MBSLAM_RETURN_IF_ERROR(log->Write(options.channels.camera_calibration, frame.utime,
                                          MakeCalibrationMessage(frame.utime, sim->intrinsics())));
      }
      mbslam::image_t image{};
      MBSLAM_RETURN_IF_ERROR(MakeImageMessage(frame, *sim, options, &image));
      MBSLAM_RETURN_IF_ERROR(log->Write(options.channels.camera_image, frame.utime, image));
      MBSLAM_RETURN_IF_ERROR(log->Write(options.channels.ground_truth, frame.utime,
                                        MakeGroundTruthMessage(frame, sim->scene().scenario)));
    }
    ++summary->frames;
    if (progress) {
      progress(k);
    }
  }
  if (log) {
    while (next_odometry < odometry.size()) {
      const auto& o = odometry[next_odometry++];
      MBSLAM_RETURN_IF_ERROR(
          log->Write(options.channels.odometry, o.utime, MakeOdometryMessage(o)));
    }
    log->Flush();
    summary->lcm_events = log->events_written();
    log.reset();
  }
  if (files) {
    MBSLAM_RETURN_IF_ERROR(files->Finish());
  }
  summary->odometry_samples = static_cast<int>(odometry.size());
  summary->mean_moving_fraction = summary->frames > 0 ? fraction_sum / summary->frames : 0.0;

  if (options.write_files) {
    const SimOptions& so = sim->options();
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically((root / "scenario.yaml").string(),
                                                 "# mbslam-sim: scenario " + so.scenario + " (" +
                                                     ScenarioDescription(so.scenario) + ")\n" +
                                                     OptionsToYaml(so)));
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically((root / "calibration.yaml").string(),
                                                 CameraIntrinsicsToYaml(sim->intrinsics())));
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically((root / "timestamps.txt").string(), timestamps));
    MBSLAM_RETURN_IF_ERROR(eval::WriteTumTrajectory((root / "cam_trajectory.tum").string(),
                                                    cam_traj,
                                                    "world_from_cam, scenario " + so.scenario));
    MBSLAM_RETURN_IF_ERROR(MakeDirs((root / "objects").string()));
    std::string objects_yaml =
        "# moving bodies: id (mask value), name, full box size along body x y z (m),\n"
        "# body origin at the box centre, x forward, z up\nobjects:\n";
    for (size_t i = 0; i < ids.size(); ++i) {
      const SceneBody& body =
          sim->scene().bodies[static_cast<size_t>(sim->scene().BodyIndex(ids[i]))];
      MBSLAM_RETURN_IF_ERROR(eval::WriteTumTrajectory(
          (root / "objects" / (std::to_string(ids[i]) + ".tum")).string(), object_traj[i],
          "world_from_object, id " + std::to_string(ids[i]) + " (" + body.name + ")"));
      objects_yaml +=
          "  - id: " + std::to_string(ids[i]) + "\n    name: " + body.name +
          "\n    extent: " + Vec3Yaml(body.extent) +
          "\n    first_frame: 0\n    last_frame: " + std::to_string(sim->num_frames() - 1) +
          "\n    frames_visible: " + std::to_string(summary->frames_visible[i]) + "\n";
    }
    if (ids.empty()) {
      objects_yaml += "  []\n";
    }
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically((root / "objects.yaml").string(), objects_yaml));
    if (sim->has_odometry()) {
      eval::Trajectory noisy, truth;
      for (const auto& o : sim->odometry()) {
        noisy.push_back({o.utime, o.odom_from_base});
      }
      for (const auto& o : sim->odometry_truth()) {
        truth.push_back({o.utime, o.odom_from_base});
      }
      MBSLAM_RETURN_IF_ERROR(eval::WriteTumTrajectory((root / "odometry.tum").string(), noisy,
                                                      "odom_from_base, wheel odometry with noise"));
      MBSLAM_RETURN_IF_ERROR(eval::WriteTumTrajectory((root / "odometry_truth.tum").string(), truth,
                                                      "odom_from_base, true"));
      const Rigid3d e = *sim->base_from_cam();
      std::ostringstream ext;
      ext.precision(12);
      ext << "# base_from_cam: camera pose in the robot base frame (base x forward, y left, z up;\n"
          << "# camera x right, y down, z forward)\n"
          << "translation: " << Vec3Yaml(e.translation) << "  # m\n"
          << "quaternion: [" << e.rotation.w() << ", " << e.rotation.x() << ", " << e.rotation.y()
          << ", " << e.rotation.z() << "]  # [w, x, y, z]\n";
      MBSLAM_RETURN_IF_ERROR(WriteStringAtomically((root / "extrinsic.yaml").string(), ext.str()));
    }
    if (options.write_points) {
      MBSLAM_RETURN_IF_ERROR(MakeDirs((root / "points").string()));
      for (const auto& body : sim->scene().bodies) {
        std::string text = "# ground-truth surface points of body " + std::to_string(body.id) +
                           " (" + body.name + "), body frame: x y z (m)\n";
        char buf[96];
        for (const auto& p : sim->SurfacePoints(body.id)) {
          std::snprintf(buf, sizeof(buf), "%.6f %.6f %.6f\n", p.x(), p.y(), p.z());
          text += buf;
        }
        MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(
            (root / "points" / (std::to_string(body.id) + ".txt")).string(), text));
      }
    }
  }
  summary->total_seconds = 1e-6 * static_cast<double>(MonotonicUtime() - t_start);
  return Status::Ok();
}

}  // namespace sim
}  // namespace mbslam
