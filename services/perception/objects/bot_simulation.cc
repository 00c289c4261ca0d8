#include "services/perception/objects/bot_simulation.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "services/perception/objects/random.h"

namespace mbslam {
namespace {

constexpr double kWallY = 12.0;     // building facades at y = +-kWallY (m)
constexpr double kFarWallX = 90.0;  // end of the street (m)
constexpr double kWallHeight = 10.0;

struct CameraScenario {
  double height;  // (m)
  double speed;   // mean forward speed (m/s)
  double surge;   // forward speed variation amplitude (m/s)
  double surge_hz;
  double bob;  // vertical amplitude (m)
  double bob_hz;
  double sway;  // lateral amplitude (m)
  double sway_hz;
  double pitch;  // (rad)
  double yaw;    // (rad)
  double roll;   // (rad)
};

struct TargetScenario {
  Eigen::Vector3d size;      // length, width, height (m)
  Eigen::Vector2d start;     // ground position of the centre at t = 0 (m)
  Eigen::Vector2d velocity;  // (m/s)
};

CameraScenario CameraFor(BotSimCamera camera) {
  if (camera == BotSimCamera::kCar) {
    // Speed varies by +-1.5 m/s over 5 s (traffic), the suspension bobs a few mm.
    return {1.4, 6.0, 1.5, 0.2, 0.006, 2.3, 0.0, 0.5, 0.003, 0.004, 0.002};
  }
  // Walking: the pace surges with each step, the camera bobs, sways and turns a little.
  return {1.5, 1.2, 0.1, 1.8, 0.04, 1.8, 0.03, 0.9, 0.026, 0.035, 0.017};
}

TargetScenario TargetFor(BotSimCamera camera, BotSimTarget target) {
  if (camera == BotSimCamera::kCar) {
    if (target == BotSimTarget::kFollowing) {
      return {Eigen::Vector3d(4.2, 1.8, 1.5), Eigen::Vector2d(17.0, 0.3),
              Eigen::Vector2d(5.0, 0.0)};
    }
    return {Eigen::Vector3d(4.2, 1.8, 1.5), Eigen::Vector2d(26.0, 7.0), Eigen::Vector2d(0.0, -4.0)};
  }
  if (target == BotSimTarget::kFollowing) {
    return {Eigen::Vector3d(0.5, 0.6, 1.75), Eigen::Vector2d(8.0, 0.4), Eigen::Vector2d(1.0, 0.0)};
  }
  return {Eigen::Vector3d(0.5, 0.6, 1.75), Eigen::Vector2d(9.0, 3.5), Eigen::Vector2d(0.0, -1.2)};
}

// world_from_cam at time t: camera z forward along world x, x right (= -y), y down (= -z),
// turned by the wiggle.
Rigid3d WorldFromCam(const CameraScenario& c, double wiggle, double t) {
  const double w = 2.0 * M_PI;
  // x(t) = integral of speed + wiggle * surge * sin(w f t), starting at 0.
  const double surge = wiggle * c.surge / (w * c.surge_hz) * (1.0 - std::cos(w * c.surge_hz * t));
  const Eigen::Vector3d position(c.speed * t + surge,
                                 wiggle * c.sway * std::sin(w * c.sway_hz * t + 0.5),
                                 c.height + wiggle * c.bob * std::sin(w * c.bob_hz * t));
  Eigen::Matrix3d base;
  base << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  const Eigen::Matrix3d wiggle_rotation =
      (Eigen::AngleAxisd(wiggle * c.yaw * std::sin(w * 0.5 * t), Eigen::Vector3d::UnitZ()) *
       Eigen::AngleAxisd(wiggle * c.pitch * std::sin(w * c.bob_hz * t + 1.0),
                         Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(wiggle * c.roll * std::sin(w * c.sway_hz * t), Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  return Rigid3d(Eigen::Matrix3d(wiggle_rotation * base), position);
}

Eigen::Vector2d Noise2(ParticleRng* rng, double sigma) {
  return Eigen::Vector2d(rng->Normal(0.0, sigma), rng->Normal(0.0, sigma));
}

// A feature point on the target: position and outward face normal in the target frame.
struct SurfacePoint {
  Eigen::Vector3d position;
  Eigen::Vector3d normal;
};

// Points on the box's faces (not the bottom), uniform by area, in the target frame.
std::vector<SurfacePoint> BoxSurfacePoints(const Eigen::Vector3d& size, int count,
                                           ParticleRng* rng) {
  const double L = size.x(), W = size.y(), H = size.z();
  const double areas[5] = {W * H, W * H, L * H, L * H, L * W};  // +x, -x, +y, -y, top
  double total = 0.0;
  for (double a : areas) total += a;
  std::vector<SurfacePoint> points;
  for (int i = 0; i < count; ++i) {
    double u = rng->Uniform() * total;
    int face = 0;
    while (face < 4 && u > areas[face]) u -= areas[face++];
    const double a = rng->Uniform(-0.5, 0.5), b = rng->Uniform(-0.5, 0.5);
    SurfacePoint p;
    switch (face) {
      case 0:
        p = {Eigen::Vector3d(0.5 * L, a * W, b * H), Eigen::Vector3d::UnitX()};
        break;
      case 1:
        p = {Eigen::Vector3d(-0.5 * L, a * W, b * H), -Eigen::Vector3d::UnitX()};
        break;
      case 2:
        p = {Eigen::Vector3d(a * L, 0.5 * W, b * H), Eigen::Vector3d::UnitY()};
        break;
      case 3:
        p = {Eigen::Vector3d(a * L, -0.5 * W, b * H), -Eigen::Vector3d::UnitY()};
        break;
      default:
        p = {Eigen::Vector3d(a * L, b * W, 0.5 * H), Eigen::Vector3d::UnitZ()};
        break;
    }
    points.push_back(p);
  }
  return points;
}

// The box is convex: a point is seen when its face turns toward the camera.
bool Visible(const SurfacePoint& p, const Rigid3d& world_from_target,
             const Eigen::Vector3d& camera_center) {
  const Eigen::Vector3d position = world_from_target * p.position;
  const Eigen::Vector3d normal = world_from_target.rotation * p.normal;
  return normal.dot(camera_center - position) > 0.0;
}

// Camera depth at which the ray centre + z * ray first meets the static scene.
double SceneDepth(const Eigen::Vector3d& center, const Eigen::Vector3d& ray) {
  double best = std::numeric_limits<double>::infinity();
  const auto consider = [&](double z) {
    if (z > 0.0 && std::isfinite(z)) best = std::min(best, z);
  };
  if (ray.z() < 0.0) consider(-center.z() / ray.z());
  if (std::abs(ray.y()) > 1e-12) {
    consider((kWallY - center.y()) / ray.y());
    consider((-kWallY - center.y()) / ray.y());
  }
  if (ray.x() > 1e-12) consider((kFarWallX - center.x()) / ray.x());
  return best;
}

}  // namespace

const char* BotSimCameraName(BotSimCamera camera) {
  return camera == BotSimCamera::kCar ? "car" : "handheld";
}

const char* BotSimTargetName(BotSimTarget target) {
  return target == BotSimTarget::kFollowing ? "following" : "crossing";
}

Status SimulateBotSequence(const BotSimOptions& o, BotSimSequence* sequence) {
  if (sequence == nullptr) return Status::Error("SimulateBotSequence: null output");
  if (!(o.fps > 0.0) || !(o.duration_s > 0.0) || !(o.focal_px > 0.0) || o.num_target_points < 3 ||
      !(o.sfm_relative_scale > 0.0)) {
    return Status::Error("SimulateBotSequence: bad options");
  }
  ParticleRng rng(o.seed);
  BotSimSequence& seq = *sequence;
  seq = BotSimSequence();
  seq.options = o;
  const CameraScenario cam = CameraFor(o.camera);
  const TargetScenario target = TargetFor(o.camera, o.target);
  seq.target_size = target.size;

  // Static map points: ground, facades, outliers.
  const int n_static = o.num_static_points;
  const int n_outliers = static_cast<int>(o.static_outlier_ratio * n_static);
  const int n_walls = (n_static - n_outliers) / 4;
  const int n_ground = n_static - n_outliers - n_walls;
  for (int i = 0; i < n_ground; ++i) {
    seq.static_points.emplace_back(rng.Uniform(-5.0, kFarWallX), rng.Uniform(-kWallY, kWallY),
                                   rng.Normal(0.0, o.ground_point_noise));
  }
  for (int i = 0; i < n_walls; ++i) {
    seq.static_points.emplace_back(rng.Uniform(-5.0, kFarWallX), i % 2 ? kWallY : -kWallY,
                                   rng.Uniform(0.0, kWallHeight));
  }
  for (int i = 0; i < n_outliers; ++i) {
    seq.static_points.emplace_back(rng.Uniform(-5.0, kFarWallX), rng.Uniform(-kWallY, kWallY),
                                   rng.Uniform(0.0, kWallHeight));
  }
  const Rigid3d first_world_from_cam = WorldFromCam(cam, o.wiggle_scale, 0.0);
  const Eigen::Vector3d up_hint = -first_world_from_cam.RotationMatrix().col(1);
  MBSLAM_RETURN_IF_ERROR(EstimateGroundPlane(seq.static_points, up_hint, &seq.ground_plane)
                             .WithContext("SimulateBotSequence"));

  // Feature points; the reference point is the centroid of those seen in the first image
  // (a fixed point of the object, as a perception core would keep it).
  const std::vector<SurfacePoint> points = BoxSurfacePoints(target.size, o.num_target_points, &rng);
  const double heading = std::atan2(target.velocity.y(), target.velocity.x());
  const Eigen::Matrix3d R_wt =
      Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  {
    const Rigid3d world_from_target0(
        R_wt, Eigen::Vector3d(target.start.x(), target.start.y(), 0.5 * target.size.z()));
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int seen = 0;
    for (const SurfacePoint& p : points) {
      if (!Visible(p, world_from_target0, first_world_from_cam.translation)) continue;
      sum += p.position;
      ++seen;
    }
    if (seen == 0) return Status::Error("SimulateBotSequence: target not visible");
    seq.reference_in_target = sum / seen;
  }
  const Eigen::Vector3d ref = seq.reference_in_target;
  const int frames = static_cast<int>(std::floor(o.duration_s * o.fps)) + 1;
  for (int k = 0; k < frames; ++k) {
    const double t = k / o.fps;
    BotSimFrame f;
    f.utime = static_cast<int64_t>(std::llround(t * 1e6));
    const Rigid3d world_from_cam = WorldFromCam(cam, o.wiggle_scale, t);
    f.cam_from_world = world_from_cam.Inverse();
    const Eigen::Vector2d ground = target.start + t * target.velocity;
    f.world_from_target =
        Rigid3d(R_wt, Eigen::Vector3d(ground.x(), ground.y(), 0.5 * target.size.z()));
    f.target_velocity = Eigen::Vector3d(target.velocity.x(), target.velocity.y(), 0.0);
    f.reference_in_world = f.world_from_target * ref;

    BotObservation& obs = f.observation;
    obs.utime = f.utime;
    obs.cam_from_world = f.cam_from_world;
    obs.focal_px = o.focal_px;
    const Eigen::Vector3d ref_cam = f.cam_from_world * f.reference_in_world;
    const Eigen::Vector2d ref_xy = ref_cam.head<2>() / ref_cam.z();
    f.visible = ref_cam.z() > 0.5 && std::abs(ref_xy.x()) * o.focal_px < 320.0 &&
                std::abs(ref_xy.y()) * o.focal_px < 240.0;
    obs.xy = ref_xy + Noise2(&rng, o.bearing_noise_px / o.focal_px);
    for (const SurfacePoint& p : points) {
      if (!Visible(p, f.world_from_target, world_from_cam.translation)) continue;
      const Eigen::Vector3d pc = f.cam_from_world * (f.world_from_target * p.position);
      if (pc.z() <= 0.1) continue;
      obs.track_xy.push_back(pc.head<2>() / pc.z() + Noise2(&rng, o.track_noise_px / o.focal_px));
    }
    const Eigen::Vector3d ray = world_from_cam.rotation * obs.xy.homogeneous();
    obs.depth_bound = DepthRange{o.depth_bound_near, SceneDepth(world_from_cam.translation, ray)};
    obs.ground_plane = seq.ground_plane.plane;
    if (t + 1e-9 >= o.sfm_start_s) {
      const Rigid3d cam_from_target = f.cam_from_world * f.world_from_target;
      const Eigen::Vector3d rot_noise(rng.Normal(0.0, o.sfm_rotation_noise_rad),
                                      rng.Normal(0.0, o.sfm_rotation_noise_rad),
                                      rng.Normal(0.0, o.sfm_rotation_noise_rad));
      const double tn = o.sfm_translation_noise_ratio * cam_from_target.translation.norm();
      const Eigen::Vector3d t_noise(rng.Normal(0.0, tn), rng.Normal(0.0, tn), rng.Normal(0.0, tn));
      SfmObservation sfm;
      sfm.map_id = 1;
      sfm.cam_from_obj =
          Rigid3d(Eigen::Matrix3d(ExpSO3(rot_noise) * cam_from_target.RotationMatrix()),
                  (cam_from_target.translation + t_noise) / o.sfm_relative_scale);
      sfm.reference_in_obj = ref / o.sfm_relative_scale;
      obs.sfm = sfm;
    }
    seq.frames.push_back(f);
  }
  return Status::Ok();
}

double BotRunResult::HitRate(int64_t horizon_us) const {
  int hits = 0, count = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    const int64_t target_utime = utimes[k] + horizon_us;
    const auto it = std::lower_bound(utimes.begin(), utimes.end(), target_utime);
    if (it == utimes.end() || *it != target_utime) continue;
    const size_t j = static_cast<size_t>(it - utimes.begin());
    for (const PredictedVolume& v : frames[k].volumes) {
      if (v.horizon_us != horizon_us) continue;
      ++count;
      hits += v.Contains(truth_centers[j]) ? 1 : 0;
    }
  }
  return count > 0 ? static_cast<double>(hits) / count : -1.0;
}

const BotRunFrame& BotRunResult::At(double t_s) const {
  size_t best = 0;
  for (size_t k = 0; k < frames.size(); ++k) {
    if (std::abs(frames[k].t_s - t_s) < std::abs(frames[best].t_s - t_s)) best = k;
  }
  return frames[best];
}

Status RunBotSequence(const BotSimSequence& sequence, const BearingOnlyTrackerOptions& options,
                      int64_t object_id, BotRunResult* result) {
  if (result == nullptr) return Status::Error("RunBotSequence: null output");
  if (sequence.frames.empty()) return Status::Error("RunBotSequence: empty sequence");
  *result = BotRunResult();
  BearingOnlyTracker tracker(options, object_id);
  ObjectExtentEstimator extent;
  const int64_t t0 = sequence.frames.front().utime;
  for (size_t k = 0; k < sequence.frames.size(); ++k) {
    const BotSimFrame& f = sequence.frames[k];
    if (k == 0) {
      if (!f.visible) return Status::Error("RunBotSequence: target not visible at the start");
      MBSLAM_RETURN_IF_ERROR(tracker.Initialize(f.observation));
    } else if (f.visible) {
      MBSLAM_RETURN_IF_ERROR(tracker.Update(f.observation));
    } else {
      MBSLAM_RETURN_IF_ERROR(tracker.Predict(f.utime, f.observation.ground_plane));
    }
    const BotEstimate e = tracker.Estimate();
    if (f.visible && e.depth > 0.0) {
      // Too few tracks just leave the extent as it was.
      static_cast<void>(extent.Update(f.cam_from_world, f.observation.track_xy, f.observation.xy,
                                      e.depth, sequence.ground_plane.plane.normal));
    }
    BotRunFrame r;
    r.t_s = static_cast<double>(f.utime - t0) * 1e-6;
    r.depth_true = (f.cam_from_world * f.reference_in_world).z();
    r.depth_mean = e.depth;
    r.depth_sigma = e.depth_sigma;
    r.position_error = (e.world_from_object.translation - f.reference_in_world).norm();
    r.range = (f.cam_from_world.Inverse().translation - f.reference_in_world).norm();
    r.ess = e.effective_sample_size;
    r.reliable = e.reliable;
    if (e.relative_scale) r.relative_scale = e.relative_scale->scale;
    r.volumes = tracker.PredictVolumes(extent.extent());
    result->frames.push_back(r);
    result->truth_centers.push_back(f.world_from_target.translation);
    result->utimes.push_back(f.utime);
  }
  return Status::Ok();
}

}  // namespace mbslam
