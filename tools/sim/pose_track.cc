#include "tools/sim/pose_track.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace mbslam {
namespace sim {

PoseTrack PoseTrack::Sample(const std::function<Rigid3d(int64_t utime)>& world_from_body,
                            int64_t begin_utime, int64_t end_utime, int64_t step_us) {
  PoseTrack track;
  track.begin_utime_ = begin_utime;
  track.step_us_ = std::max<int64_t>(1, step_us);
  const int64_t n = std::max<int64_t>(0, (end_utime - begin_utime) / track.step_us_) + 1;
  track.samples_.reserve(static_cast<size_t>(n) + 1);
  for (int64_t i = 0; i < n; ++i) {
    track.samples_.push_back(world_from_body(begin_utime + i * track.step_us_));
  }
  // Make sure end_utime itself is covered.
  if (track.end_utime() < end_utime) {
    track.samples_.push_back(world_from_body(begin_utime + n * track.step_us_));
  }
  return track;
}

PoseTrack PoseTrack::Constant(const Rigid3d& world_from_body) {
  PoseTrack track;
  track.samples_.push_back(world_from_body);
  return track;
}

Rigid3d PoseTrack::WorldFromBody(int64_t utime) const {
  if (samples_.empty()) {
    return Rigid3d();
  }
  if (samples_.size() == 1 || utime <= begin_utime_) {
    return samples_.front();
  }
  const int64_t offset = utime - begin_utime_;
  const int64_t index = offset / step_us_;
  if (index >= static_cast<int64_t>(samples_.size()) - 1) {
    return samples_.back();
  }
  const int64_t rem = offset - index * step_us_;
  const Rigid3d& a = samples_[static_cast<size_t>(index)];
  if (rem == 0) {
    return a;
  }
  const Rigid3d& b = samples_[static_cast<size_t>(index + 1)];
  return Rigid3d::Interpolate(a, b, static_cast<double>(rem) / static_cast<double>(step_us_));
}

MotionState PoseTrack::StateAt(int64_t utime) const {
  MotionState state;
  state.world_from_body = WorldFromBody(utime);
  if (samples_.size() < 2) {
    return state;
  }
  const Rigid3d before = WorldFromBody(utime - step_us_);
  const Rigid3d after = WorldFromBody(utime + step_us_);
  const double dt = 2e-6 * static_cast<double>(step_us_);
  state.linear_velocity = (after.translation - before.translation) / dt;
  state.angular_velocity =
      LogSO3((after.rotation * before.rotation.conjugate()).toRotationMatrix()) / dt;
  return state;
}

PlanarPath::PlanarPath(double x, double y, double yaw, double speed) {
  State s;
  s.x = x;
  s.y = y;
  s.yaw = yaw;
  s.speed = std::max(0.0, speed);
  knots_.push_back(s);
}

void PlanarPath::Advance(double duration_s, double acceleration, double yaw_rate, bool wait) {
  const int steps = static_cast<int>(std::lround(std::max(0.0, duration_s) / kStepS));
  for (int i = 0; i < steps; ++i) {
    State s = knots_.back();
    const double v0 = wait ? 0.0 : s.speed;
    const double v1 = wait ? 0.0 : std::max(0.0, v0 + acceleration * kStepS);
    const bool moving = v0 > 0.0 || v1 > 0.0;
    const double w = moving ? yaw_rate : 0.0;
    // Midpoint rule for position (exact for straight segments, 1e-9 m per step else).
    const double yaw_mid = s.yaw + 0.5 * w * kStepS;
    const double v_mid = 0.5 * (v0 + v1);
    s.x += v_mid * std::cos(yaw_mid) * kStepS;
    s.y += v_mid * std::sin(yaw_mid) * kStepS;
    s.yaw += w * kStepS;
    s.speed = v1;
    s.yaw_rate = w;
    knots_.push_back(s);
  }
}

PlanarPath& PlanarPath::Wait(double duration_s) {
  Advance(duration_s, 0.0, 0.0, true);
  return *this;
}

PlanarPath& PlanarPath::Drive(double duration_s, double acceleration, double yaw_rate) {
  Advance(duration_s, acceleration, yaw_rate, false);
  return *this;
}

PlanarPath& PlanarPath::RampTo(double speed, double duration_s, double yaw_rate) {
  if (duration_s <= 0.0) {
    return *this;
  }
  const double a = (std::max(0.0, speed) - knots_.back().speed) / duration_s;
  Advance(duration_s, a, yaw_rate, false);
  return *this;
}

PlanarPath& PlanarPath::Turn(double angle_rad, double yaw_rate_abs) {
  if (yaw_rate_abs <= 0.0 || angle_rad == 0.0) {
    return *this;
  }
  const double rate = angle_rad > 0.0 ? yaw_rate_abs : -yaw_rate_abs;
  Advance(std::abs(angle_rad) / yaw_rate_abs, 0.0, rate, false);
  return *this;
}

double PlanarPath::duration_s() const { return static_cast<double>(knots_.size() - 1) * kStepS; }

PlanarPath::State PlanarPath::At(double t_s) const {
  if (t_s <= 0.0) {
    State s = knots_.front();
    s.x += s.speed * std::cos(s.yaw) * t_s;
    s.y += s.speed * std::sin(s.yaw) * t_s;
    s.yaw_rate = 0.0;
    return s;
  }
  const double end = duration_s();
  if (t_s >= end) {
    State s = knots_.back();
    const double dt = t_s - end;
    const double w = s.speed > 0.0 ? s.yaw_rate : 0.0;
    if (std::abs(w) < 1e-12) {
      s.x += s.speed * std::cos(s.yaw) * dt;
      s.y += s.speed * std::sin(s.yaw) * dt;
    } else {  // circular arc
      const double yaw1 = s.yaw + w * dt;
      s.x += s.speed / w * (std::sin(yaw1) - std::sin(s.yaw));
      s.y -= s.speed / w * (std::cos(yaw1) - std::cos(s.yaw));
      s.yaw = yaw1;
    }
    return s;
  }
  const double f = t_s / kStepS;
  const size_t i = std::min(static_cast<size_t>(f), knots_.size() - 2);
  const double a = f - static_cast<double>(i);
  const State& p = knots_[i];
  const State& q = knots_[i + 1];
  State s;
  s.x = p.x + a * (q.x - p.x);
  s.y = p.y + a * (q.y - p.y);
  s.yaw = p.yaw + a * (q.yaw - p.yaw);
  s.speed = p.speed + a * (q.speed - p.speed);
  s.yaw_rate = q.yaw_rate;
  return s;
}

PoseTrack PlanarPath::ToTrack(int64_t start_utime, int64_t begin_utime, int64_t end_utime,
                              double height) const {
  return PoseTrack::Sample(
      [&](int64_t utime) {
        const State s = At(1e-6 * static_cast<double>(utime - start_utime));
        return PlanarPose(s.x, s.y, height, s.yaw);
      },
      begin_utime, end_utime);
}

Rigid3d PlanarPose(double x, double y, double z, double yaw) {
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())),
                 Eigen::Vector3d(x, y, z));
}

Rigid3d ForwardCameraMount(const Eigen::Vector3d& translation, double pitch_down_rad,
                           double yaw_left_rad) {
  // Columns: camera x (right) = -base y, camera y (down) = -base z, camera z = base x.
  Eigen::Matrix3d base_from_cam_level;
  base_from_cam_level << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  // Pitch down: rotate about base y (left axis) by +pitch (x forward tilts towards -z).
  const Eigen::Matrix3d yaw =
      Eigen::AngleAxisd(yaw_left_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d pitch =
      Eigen::AngleAxisd(pitch_down_rad, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return Rigid3d(Eigen::Matrix3d(yaw * pitch * base_from_cam_level), translation);
}

SmoothNoise3::SmoothNoise3(uint64_t seed, double rms, double f_min_hz, double f_max_hz, int terms) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> freq(f_min_hz, f_max_hz);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  std::uniform_real_distribution<double> weight(0.5, 1.0);
  for (auto& axis : terms_) {
    double sum_sq = 0.0;
    for (int i = 0; i < terms; ++i) {
      Term t{weight(rng), freq(rng), phase(rng)};
      sum_sq += 0.5 * t.amplitude * t.amplitude;  // mean square of a sinusoid
      axis.push_back(t);
    }
    const double scale = sum_sq > 0.0 ? rms / std::sqrt(sum_sq) : 0.0;
    for (Term& t : axis) {
      t.amplitude *= scale;
    }
  }
}

Eigen::Vector3d SmoothNoise3::At(double t_s) const {
  Eigen::Vector3d out = Eigen::Vector3d::Zero();
  for (int a = 0; a < 3; ++a) {
    for (const Term& t : terms_[a]) {
      out[a] += t.amplitude * std::sin(2.0 * M_PI * t.frequency * t_s + t.phase);
    }
  }
  return out;
}

}  // namespace sim
}  // namespace mbslam
