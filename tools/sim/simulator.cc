#include "tools/sim/simulator.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/util/logging.h"
#include "tools/sim/scenarios.h"

namespace mbslam {
namespace sim {

CameraIntrinsics SimCameraOptions::Intrinsics() const {
  CameraIntrinsics c;
  c.name = name;
  c.width = width;
  c.height = height;
  const double focal = 525.0 * width / 640.0;
  c.fx = fx > 0.0 ? fx : focal;
  c.fy = fy > 0.0 ? fy : focal;
  c.cx = cx >= 0.0 ? cx : 0.5 * (width - 1);
  c.cy = cy >= 0.0 ? cy : 0.5 * (height - 1);
  c.model = DistortionModel::kNone;
  return c;
}

int64_t SimOptions::FrameUtime(int k) const {
  return start_utime + static_cast<int64_t>(std::llround(static_cast<double>(k) * 1e6 / fps));
}

double SimFrame::MovingFraction() const {
  if (mask.empty()) {
    return 0.0;
  }
  return static_cast<double>(cv::countNonZero(mask)) / static_cast<double>(mask.total());
}

Simulator::~Simulator() = default;

std::unique_ptr<Simulator> Simulator::Create(const SimOptions& options, Status* status) {
  if (!options.Check()) {
    *status = Status::Error("simulator options: " + LastOptionError());
    return nullptr;
  }
  std::unique_ptr<Simulator> sim(new Simulator());
  sim->options_ = options;
  sim->intrinsics_ = options.camera.Intrinsics();
  *status = sim->intrinsics_.Validate();
  if (!status->ok()) {
    return nullptr;
  }
  *status = BuildScenario(options, &sim->scene_);
  if (!status->ok()) {
    return nullptr;
  }
  sim->renderer_ = Renderer::Create(sim->scene_, sim->intrinsics_, options.image.render, status);
  if (!sim->renderer_) {
    return nullptr;
  }
  // The renderer keeps its own copies of the textures: free ours.
  for (auto& t : sim->scene_.textures) {
    t = cv::Mat();
  }

  const uint64_t seed = static_cast<uint64_t>(options.seed);
  for (size_t b = 0; b < sim->scene_.bodies.size(); ++b) {
    const SceneBody& body = sim->scene_.bodies[b];
    const bool is_static = body.id == 0;
    sim->surface_points_.push_back(SampleSurfacePoints(
        body, is_static ? options.static_points_per_m2 : options.object_points_per_m2,
        std::min(is_static ? 2000 : 200, options.max_points_per_body), options.max_points_per_body,
        seed * 1000003ULL + static_cast<uint64_t>(body.id) + 11));
  }
  if (sim->has_odometry()) {
    sim->GenerateOdometry();
  }
  *status = Status::Ok();
  return sim;
}

Rigid3d Simulator::WorldFromCam(int64_t utime) const { return scene_.camera.WorldFromBody(utime); }

Rigid3d Simulator::WorldFromBody(int id, int64_t utime) const {
  const int index = scene_.BodyIndex(id);
  if (index < 0) {
    return Rigid3d();
  }
  return scene_.bodies[static_cast<size_t>(index)].track.WorldFromBody(utime);
}

std::vector<int> Simulator::MovingBodyIds() const {
  std::vector<int> ids;
  for (const auto& b : scene_.bodies) {
    if (b.id > 0) {
      ids.push_back(b.id);
    }
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

const std::vector<Eigen::Vector3d>& Simulator::SurfacePoints(int id) const {
  static const std::vector<Eigen::Vector3d> kEmpty;
  const int index = scene_.BodyIndex(id);
  return index < 0 ? kEmpty : surface_points_[static_cast<size_t>(index)];
}

std::optional<Rigid3d> Simulator::base_from_cam() const {
  if (!scene_.base) {
    return std::nullopt;
  }
  return scene_.base_from_cam;
}

std::vector<Rigid3d> Simulator::CamFromBodies(int64_t utime) const {
  const Rigid3d cam_from_world = WorldFromCam(utime).Inverse();
  std::vector<Rigid3d> out;
  out.reserve(scene_.bodies.size());
  for (const auto& b : scene_.bodies) {
    out.push_back(cam_from_world * b.track.WorldFromBody(utime));
  }
  return out;
}

Status Simulator::FrameTruth(int k, SimFrame* frame) const {
  if (k < 0 || k >= options_.num_frames) {
    return Status::Error("frame " + std::to_string(k) + " outside [0, " +
                         std::to_string(options_.num_frames) + ")");
  }
  frame->index = k;
  frame->utime = FrameUtime(k);
  const MotionState cam = scene_.camera.StateAt(frame->utime);
  frame->world_from_cam = cam.world_from_body;
  frame->cam_linear_velocity = cam.linear_velocity;
  frame->cam_angular_velocity = cam.angular_velocity;
  frame->bodies.clear();
  for (const auto& b : scene_.bodies) {
    if (b.id == 0) {
      continue;
    }
    const MotionState s = b.track.StateAt(frame->utime);
    SimBodyState state;
    state.id = b.id;
    state.name = b.name;
    state.extent = b.extent;
    state.world_from_body = s.world_from_body;
    state.linear_velocity = s.linear_velocity;
    state.angular_velocity = s.angular_velocity;
    frame->bodies.push_back(state);
  }
  std::sort(frame->bodies.begin(), frame->bodies.end(),
            [](const SimBodyState& a, const SimBodyState& b) { return a.id < b.id; });
  return Status::Ok();
}

Status Simulator::RenderFrame(int k, SimFrame* frame, const RenderRequest& request) {
  MBSLAM_RETURN_IF_ERROR(FrameTruth(k, frame));
  frame->image_bgr.release();
  frame->image_gray.release();
  frame->mask.release();
  frame->depth.release();
  frame->points_in_cam.release();
  if (request.geometry) {
    MBSLAM_RETURN_IF_ERROR(renderer_->RenderGeometry(CamFromBodies(frame->utime), &frame->mask,
                                                     &frame->points_in_cam));
    cv::extractChannel(frame->points_in_cam, frame->depth, 2);
    std::vector<int> counts(65536, 0);
    for (int r = 0; r < frame->mask.rows; ++r) {
      const uint16_t* row = frame->mask.ptr<uint16_t>(r);
      for (int c = 0; c < frame->mask.cols; ++c) {
        ++counts[row[c]];
      }
    }
    for (auto& b : frame->bodies) {
      b.pixel_count = counts[static_cast<size_t>(b.id)];
      b.visible = b.pixel_count > 0;
    }
  }
  if (request.image) {
    const int samples = options_.image.motion_blur_samples;
    if (samples <= 1) {
      MBSLAM_RETURN_IF_ERROR(
          renderer_->RenderColor(CamFromBodies(frame->utime), &frame->image_bgr));
    } else {
      cv::Mat sum(intrinsics_.height, intrinsics_.width, CV_32FC3, cv::Scalar::all(0));
      cv::Mat sub;
      const double exposure_us = options_.image.exposure_ms * 1000.0;
      for (int i = 0; i < samples; ++i) {
        const double f = static_cast<double>(i) / (samples - 1) - 0.5;
        const int64_t t = frame->utime + static_cast<int64_t>(std::llround(f * exposure_us));
        MBSLAM_RETURN_IF_ERROR(renderer_->RenderColor(CamFromBodies(t), &sub));
        cv::accumulate(sub, sum);
      }
      sum.convertTo(frame->image_bgr, CV_8UC3, 1.0 / samples);
    }
    cv::cvtColor(frame->image_bgr, frame->image_gray, cv::COLOR_BGR2GRAY);
    if (options_.image.noise_sigma > 0.0) {
      cv::RNG rng(static_cast<uint64_t>(options_.seed) * 2654435761ULL + static_cast<uint64_t>(k) +
                  1);
      for (cv::Mat* img : {&frame->image_bgr, &frame->image_gray}) {
        cv::Mat noise(img->size(), CV_MAKETYPE(CV_32F, img->channels()));
        rng.fill(noise, cv::RNG::NORMAL, 0.0, options_.image.noise_sigma);
        cv::Mat f;
        img->convertTo(f, noise.type());
        f += noise;
        f.convertTo(*img, img->type());
      }
    }
  }
  return Status::Ok();
}

void Simulator::GenerateOdometry() {
  const SimOdometryOptions& o = options_.odometry;
  const PoseTrack& base = *scene_.base;
  const int64_t first = FrameUtime(0) + o.time_offset_us;
  const int64_t last = FrameUtime(options_.num_frames - 1);
  std::mt19937_64 rng(static_cast<uint64_t>(options_.seed) * 7919ULL + 5);
  std::normal_distribution<double> unit(0.0, 1.0);
  const double speed_scale = 1.0 + (unit(rng) >= 0.0 ? 1.0 : -1.0) * o.speed_scale_error;
  const double yaw_scale = 1.0 + (unit(rng) >= 0.0 ? 1.0 : -1.0) * o.yaw_rate_scale_error;

  // The odometry frame: the base's planar pose at the first sample.
  const Rigid3d world_from_base0 = base.WorldFromBody(first);
  const Eigen::Vector3d x_axis = world_from_base0.rotation * Eigen::Vector3d::UnitX();
  const Rigid3d world_from_odom =
      PlanarPose(world_from_base0.translation.x(), world_from_base0.translation.y(), 0.0,
                 std::atan2(x_axis.y(), x_axis.x()));
  const Rigid3d odom_from_world = world_from_odom.Inverse();

  auto measured = [&](int64_t utime, double* v, double* w) {
    const MotionState s = base.StateAt(utime);
    *v = (s.world_from_body.rotation.conjugate() * s.linear_velocity).x();
    *w = s.angular_velocity.z();
  };
  Rigid3d noisy;  // planar dead reckoning, starts at the truth's planar pose
  {
    const Rigid3d t0 = odom_from_world * world_from_base0;
    const Eigen::Vector3d ax = t0.rotation * Eigen::Vector3d::UnitX();
    noisy = PlanarPose(t0.translation.x(), t0.translation.y(), 0.0, std::atan2(ax.y(), ax.x()));
  }
  double var_xy = 0.0, var_yaw = 0.0, distance = 0.0, turned = 0.0;
  double prev_v = 0.0, prev_w = 0.0;
  int64_t prev_t = first;
  int64_t seq = 0;
  for (int64_t j = 0;; ++j) {
    const int64_t t =
        first + static_cast<int64_t>(std::llround(static_cast<double>(j) * 1e6 / o.rate_hz));
    if (t > last) {
      break;
    }
    double v_true, w_true;
    measured(t, &v_true, &w_true);
    const double v_m = v_true * speed_scale + o.speed_noise * unit(rng);
    const double w_m = w_true * yaw_scale + o.yaw_rate_bias + o.yaw_rate_noise * unit(rng);
    if (j > 0) {
      const double dt = 1e-6 * static_cast<double>(t - prev_t);
      const double v = 0.5 * (prev_v + v_m), w = 0.5 * (prev_w + w_m);
      Vector6d xi = Vector6d::Zero();
      xi[0] = v * dt;
      xi[5] = w * dt;
      noisy = noisy * Rigid3d::Exp(xi);
      distance += std::abs(v) * dt;
      turned += std::abs(w) * dt;
      var_xy += std::pow(o.speed_noise * dt, 2);
      var_yaw += std::pow(o.yaw_rate_noise * dt, 2);
    }
    prev_v = v_m;
    prev_w = w_m;
    prev_t = t;

    OdometrySample truth;
    truth.utime = t;
    truth.seq = seq;
    const MotionState s = base.StateAt(t);
    truth.odom_from_base = odom_from_world * s.world_from_body;
    truth.linear_velocity = s.world_from_body.rotation.conjugate() * s.linear_velocity;
    truth.angular_velocity = s.world_from_body.rotation.conjugate() * s.angular_velocity;
    odometry_truth_.push_back(truth);

    OdometrySample sample;
    sample.utime = t;
    sample.seq = seq++;
    sample.odom_from_base = noisy;
    sample.linear_velocity = Eigen::Vector3d(v_m, 0.0, 0.0);
    sample.angular_velocity = Eigen::Vector3d(0.0, 0.0, w_m);
    const double elapsed = 1e-6 * static_cast<double>(t - first);
    const double pos_sigma_sq = var_xy + std::pow(o.speed_scale_error * distance, 2);
    const double yaw_sigma_sq = var_yaw + std::pow(o.yaw_rate_bias * elapsed, 2) +
                                std::pow(o.yaw_rate_scale_error * turned, 2);
    sample.pose_covariance.diagonal() << pos_sigma_sq + yaw_sigma_sq * distance * distance,
        pos_sigma_sq + yaw_sigma_sq * distance * distance, 1e-6, 1e-6, 1e-6, yaw_sigma_sq + 1e-8;
    sample.twist_covariance.diagonal()
        << std::pow(o.speed_noise, 2) + std::pow(o.speed_scale_error * v_true, 2),
        1e-4, 1e-4, 1e-4, 1e-4, std::pow(o.yaw_rate_noise, 2) + std::pow(o.yaw_rate_bias, 2);
    odometry_.push_back(sample);
  }
}

}  // namespace sim
}  // namespace mbslam
