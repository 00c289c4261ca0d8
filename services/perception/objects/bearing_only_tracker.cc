#include "services/perception/objects/bearing_only_tracker.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Eigenvalues>

#include "common/util/logging.h"

namespace mbslam {
namespace {

constexpr double kUsToS = 1e-6;
// Log-weight of a particle that cannot be measured at all (behind the camera).
constexpr double kUnmeasurableLogWeight = -1e6;
// Cells of the numeric integration over the free depth when velocities are seated.
constexpr int kSeatCells = 32;

Eigen::Vector3d Normal3(ParticleRng* rng) {
  return Eigen::Vector3d(rng->Normal(), rng->Normal(), rng->Normal());
}

// Removes the component along the unit vector n.
Eigen::Vector3d InPlane(const Eigen::Vector3d& v, const Eigen::Vector3d& n) {
  return v - v.dot(n) * n;
}

// Linear-interpolated percentile of sorted values, q in [0, 1].
double SortedPercentile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const size_t i = static_cast<size_t>(std::floor(pos));
  const size_t j = std::min(i + 1, sorted.size() - 1);
  const double f = pos - static_cast<double>(i);
  return sorted[i] * (1.0 - f) + sorted[j] * f;
}

uint64_t MixSeed(int64_t seed, int64_t object_id) {
  uint64_t x = static_cast<uint64_t>(seed) * 0x9e3779b97f4a7c15ULL;
  x ^= static_cast<uint64_t>(object_id) + 0x632be59bd9b4e019ULL + (x << 6) + (x >> 2);
  return x;
}

// Unit quaternion of the rotation vector w (rad); first order below 1e-4 rad.
Eigen::Quaterniond QuaternionExp(const Eigen::Vector3d& w) {
  const double theta = w.norm();
  if (theta < 1e-4)
    return Eigen::Quaterniond(1.0, 0.5 * w.x(), 0.5 * w.y(), 0.5 * w.z()).normalized();
  const double half = 0.5 * theta;
  const Eigen::Vector3d v = (std::sin(half) / theta) * w;
  return Eigen::Quaterniond(std::cos(half), v.x(), v.y(), v.z());
}

// Translation of exp([u; w]) for the rotation vector w and u = v dt: J_l(w) u, by its
// series I + W/2 + W^2/6 below 0.1 rad (relative error below 1e-4 there).
Eigen::Vector3d StepTranslation(const Eigen::Vector3d& w, const Eigen::Vector3d& u) {
  if (w.squaredNorm() < 1e-2) {
    const Eigen::Vector3d wu = w.cross(u);
    return u + 0.5 * wu + w.cross(wu) / 6.0;
  }
  return LeftJacobianSO3(w) * u;
}

bool FiniteGroundPlane(const std::optional<GroundPlane>& plane) {
  return plane && plane->IsValid();
}

}  // namespace

// The cue set psi of one step, evaluated for the step's image.
struct BearingOnlyTracker::StepCues {
  bool has_camera = false;  // depth-based checks need the image's camera
  Eigen::Matrix3d R_cw = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t_cw = Eigen::Vector3d::Zero();
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  // camera centre, world
  double min_depth = 0.0;
  bool depth = false;  // depth bound
  double z_min = 0.0, z_max = 0.0;
  bool has_plane = false;  // the ground plane is known (ground-plane and size-bound cues)
  GroundPlane plane;
  bool ground = false;  // ground-plane cue
  double height_tolerance = 0.0;
  double below_tolerance = 0.0;
  bool size = false;  // size bound: lowest track height = h_cam + z k_lo (with the plane)
  double h_cam = 0.0, k_lo = 0.0, k_hi = 0.0;
  double max_clearance = 0.0, max_height = 0.0;

  double Depth(const Eigen::Vector3d& p) const { return R_cw.row(2).dot(p) + t_cw.z(); }
};

BearingOnlyTracker::BearingOnlyTracker(const BearingOnlyTrackerOptions& options, int64_t object_id)
    : options_(options),
      options_ok_(options.Check()),
      object_id_(object_id),
      rng_(MixSeed(options.seed, object_id)) {}

void BearingOnlyTracker::Reset() {
  rng_.Seed(MixSeed(options_.seed, object_id_));
  particles_.clear();
  initialized_ = false;
  seated_ = false;
  orientation_tracked_ = false;
  camera_velocity_.setZero();
  utime_ = 0;
  init_utime_ = 0;
  plane_.reset();
  sfm_history_.clear();
  stats_ = BotStats();
}

Status BearingOnlyTracker::CheckObservation(const BotObservation& o) const {
  if (!options_ok_) return Status::Error("bearing-only tracker options: " + LastOptionError());
  if (!o.cam_from_world.IsFinite()) return Status::Error("camera pose not finite");
  if (!o.xy.allFinite()) return Status::Error("bearing not finite");
  if (!(o.focal_px > 0.0) || !std::isfinite(o.focal_px)) {
    return Status::Error("focal length must be positive");
  }
  if (!std::isfinite(o.bearing_sigma_px) || o.bearing_sigma_px < 0.0) {
    return Status::Error("bearing sigma must be finite and >= 0");
  }
  if (o.depth_bound && (std::isnan(o.depth_bound->min) || std::isnan(o.depth_bound->max) ||
                        o.depth_bound->max < o.depth_bound->min)) {
    return Status::Error("depth bound is NaN or empty");
  }
  if (o.sfm && (!o.sfm->cam_from_obj.IsFinite() || !o.sfm->reference_in_obj.allFinite())) {
    return Status::Error("SfM observation not finite");
  }
  return Status::Ok();
}

BearingOnlyTracker::StepCues BearingOnlyTracker::MakeCues(const BotObservation* o) const {
  StepCues c;
  c.min_depth = options_.min_depth;
  c.height_tolerance = options_.ground_height_tolerance;
  c.below_tolerance = options_.below_ground_tolerance;
  c.max_clearance = options_.max_ground_clearance;
  c.max_height = options_.max_object_height;
  const std::optional<GroundPlane>& plane =
      (o != nullptr && FiniteGroundPlane(o->ground_plane)) ? o->ground_plane : plane_;
  if (FiniteGroundPlane(plane)) {
    c.has_plane = true;
    c.plane = *plane;
    c.ground = options_.cues.ground_plane;
  }
  if (o == nullptr) return c;

  c.has_camera = true;
  c.R_cw = o->cam_from_world.RotationMatrix();
  c.t_cw = o->cam_from_world.translation;
  c.center = -c.R_cw.transpose() * c.t_cw;
  if (options_.cues.depth_bound && o->depth_bound) {
    c.depth = true;
    c.z_min = o->depth_bound->min;
    c.z_max = o->depth_bound->max;
  }
  if (options_.cues.size_bound &&
      static_cast<int>(o->track_xy.size()) >= options_.size_bound_min_tracks) {
    // Height of track j at camera depth z: h_cam + z k_j, with k_j = up . R_wc [x_j; y_j; 1]
    // (up = the plane's normal, or the camera's -y axis without a plane: then only the
    // object's height is bounded).
    const Eigen::Matrix3d R_wc = c.R_cw.transpose();
    const Eigen::Vector3d up = c.has_plane ? c.plane.normal : Eigen::Vector3d(-R_wc.col(1));
    std::vector<double> k;
    k.reserve(o->track_xy.size());
    for (const Eigen::Vector2d& xy : o->track_xy) {
      if (xy.allFinite()) k.push_back(up.dot(R_wc * xy.homogeneous()));
    }
    if (static_cast<int>(k.size()) >= options_.size_bound_min_tracks) {
      std::sort(k.begin(), k.end());
      c.size = true;
      c.k_lo = SortedPercentile(k, options_.size_bound_percentile);
      c.k_hi = SortedPercentile(k, 1.0 - options_.size_bound_percentile);
      c.h_cam = c.has_plane ? c.plane.Height(c.center) : 0.0;
    }
  }
  return c;
}

bool BearingOnlyTracker::InPsi(const BotParticle& particle, const StepCues& c) const {
  double z = 0.0;
  if (c.has_camera) {
    z = c.Depth(particle.position);
    if (z < c.min_depth) return false;
    if (c.depth && (z < c.z_min || z > c.z_max)) return false;
  }
  if (c.ground) {
    const double h = c.plane.Height(particle.position);
    if (std::abs(h - particle.ground_height) > c.height_tolerance) return false;
    if (h < -c.below_tolerance) return false;
  }
  if (c.size && c.has_camera) {
    if (c.has_plane) {
      const double lowest = c.h_cam + z * c.k_lo;
      if (lowest < -c.below_tolerance || lowest > c.max_clearance) return false;
    }
    if (z * (c.k_hi - c.k_lo) > c.max_height) return false;
  }
  return true;
}

void BearingOnlyTracker::DrawInitialVelocity(BotParticle* particle, const StepCues& c) {
  // Uniform density in the shell (3D) or annulus (in the plane): the speed's CDF goes with
  // its cube or square.
  const double a = options_.init_speed_min, b = options_.init_speed_max;
  const double u = rng_.Uniform();
  const double speed = c.ground ? std::sqrt(a * a + u * (b * b - a * a))
                                : std::cbrt(a * a * a + u * (b * b * b - a * a * a));
  Eigen::Vector3d direction = Normal3(&rng_);
  if (c.ground) direction = InPlane(direction, c.plane.normal);
  const double n = direction.norm();
  particle->linear_velocity =
      n > 1e-12 ? Eigen::Vector3d(speed * direction / n) : Eigen::Vector3d::Zero();
  particle->angular_velocity.setZero();
}

Status BearingOnlyTracker::Initialize(const BotObservation& observation) {
  return InitializeImpl(observation, nullptr, 0.0);
}

Status BearingOnlyTracker::InitializeFromPoint(const BotObservation& observation,
                                               const Eigen::Vector3d& point_in_world,
                                               double depth_sigma) {
  if (!point_in_world.allFinite() || !std::isfinite(depth_sigma)) {
    ++stats_.rejected_inputs;
    return Status::Error("BearingOnlyTracker: static point or depth sigma not finite");
  }
  return InitializeImpl(observation, &point_in_world, depth_sigma);
}

Status BearingOnlyTracker::InitializeImpl(const BotObservation& o,
                                          const Eigen::Vector3d* point_in_world,
                                          double depth_sigma) {
  if (Status s = CheckObservation(o); !s.ok()) {
    ++stats_.rejected_inputs;
    return s.WithContext("BearingOnlyTracker::Initialize");
  }
  Reset();
  if (FiniteGroundPlane(o.ground_plane)) plane_ = o.ground_plane;
  const StepCues cues = MakeCues(&o);
  const Rigid3d world_from_cam = o.cam_from_world.Inverse();
  const Eigen::Vector3d ray = world_from_cam.rotation * o.xy.homogeneous();  // unit camera depth
  const Eigen::Vector3d center = world_from_cam.translation;

  // Depth prior: the depth bound (or the default range), or around the mapped depth.
  double z_lo = options_.init_depth_min, z_hi = options_.init_depth_max;
  if (options_.cues.depth_bound && o.depth_bound) {
    z_lo = std::max(o.depth_bound->min, options_.min_depth);
    if (std::isfinite(o.depth_bound->max)) z_hi = o.depth_bound->max;
  }
  z_lo = std::max(z_lo, options_.min_depth);
  if (z_hi <= z_lo) z_hi = z_lo * 1.5;
  double z_mean = 0.0, z_sigma = 0.0;
  if (point_in_world != nullptr) {
    z_mean = (o.cam_from_world * *point_in_world).z();
    if (z_mean <= options_.min_depth) {
      ++stats_.rejected_inputs;
      return Status::Error("BearingOnlyTracker::InitializeFromPoint: point is behind the camera");
    }
    z_sigma = depth_sigma > 0.0 ? depth_sigma : options_.static_depth_sigma_ratio * z_mean;
  }

  const int n = options_.num_particles;
  particles_.assign(static_cast<size_t>(n), BotParticle());
  int violations = 0;
  for (BotParticle& p : particles_) {
    bool ok = false;
    for (int attempt = 0; attempt < options_.max_rejection_tries && !ok; ++attempt) {
      double z =
          point_in_world != nullptr ? rng_.Normal(z_mean, z_sigma) : rng_.Uniform(z_lo, z_hi);
      z = std::max(z, options_.min_depth);
      p.position = center + z * ray;
      p.ground_height = cues.has_plane ? cues.plane.Height(p.position) : 0.0;
      ok = InPsi(p, cues);
    }
    DrawInitialVelocity(&p, cues);
    p.init_position = p.position;
    p.log_weight = ok ? 0.0 : std::log(options_.violation_weight);
    violations += ok ? 0 : 1;
  }
  initialized_ = true;
  seated_ = false;
  utime_ = o.utime;
  init_utime_ = o.utime;
  init_world_from_cam_ = world_from_cam;
  cam_from_world_ = o.cam_from_world;
  stats_.last_violation_share = static_cast<double>(violations) / n;
  NormalizeAndResample();
  RecordSfm(o);
  return Status::Ok();
}

void BearingOnlyTracker::RebaseGroundHeights(const std::optional<GroundPlane>& plane) {
  if (!FiniteGroundPlane(plane)) return;
  const bool changed = !plane_ || (plane_->normal - plane->normal).norm() > 1e-9 ||
                       std::abs(plane_->offset - plane->offset) > 1e-9;
  if (!changed) return;
  // The same points, measured from the new plane (a refined static map).
  for (BotParticle& p : particles_) {
    const double old_h = plane_ ? plane_->Height(p.position) : 0.0;
    const double offset = p.ground_height - old_h;  // how far the particle drifted from its height
    p.ground_height = plane->Height(p.position) + (plane_ ? offset : 0.0);
  }
  plane_ = plane;
}

std::vector<double> BearingOnlyTracker::NoiseScales() const {
  std::vector<double> scales(particles_.size(), 1.0);
  if (!options_.depth_relative_noise || particles_.empty()) return scales;
  const Eigen::Matrix3d R_cw = cam_from_world_.RotationMatrix();
  const double tz = cam_from_world_.translation.z();
  double sum_w = 0.0, sum_wz = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    const double z = std::max(R_cw.row(2).dot(particles_[i].position) + tz, options_.min_depth);
    scales[i] = z;
    const double w = std::exp(particles_[i].log_weight);
    sum_w += w;
    sum_wz += w * z;
  }
  if (!(sum_w > 0.0) || !(sum_wz > 0.0)) {
    std::fill(scales.begin(), scales.end(), 1.0);
    return scales;
  }
  const double mean_z = sum_wz / sum_w;
  for (double& k : scales) k /= mean_z;
  return scales;
}

void BearingOnlyTracker::Propagate(double dt, const StepCues& c,
                                   std::vector<double>* truncation_log_weight) {
  truncation_log_weight->assign(particles_.size(), 0.0);
  const std::vector<double> noise_scale = NoiseScales();
  const double log_violation = std::log(options_.violation_weight);
  const double sq = std::sqrt(std::max(dt, 0.0));
  const double sv = options_.accel_sigma * sq;
  const double sw = options_.angular_accel_sigma * sq;
  const double sp = options_.position_sigma * sq;
  const double sr = options_.rotation_sigma * sq;
  const double sh = options_.ground_height_sigma * sq;
  const Eigen::Vector3d n = c.plane.normal;
  int violations = 0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    const BotParticle& prior = particles_[i];
    const double k = noise_scale[i];
    BotParticle candidate = prior;
    bool ok = false;
    int attempts = 0;
    while (!ok && attempts < options_.max_rejection_tries) {
      ++attempts;
      candidate = prior;
      if (dt > 0.0) {
        // Twist random walk (white-noise acceleration), then the constant-velocity step.
        Eigen::Vector3d e = (k * sv) * Normal3(&rng_);
        if (c.ground) e = InPlane(e, n);
        candidate.linear_velocity += e;
        Eigen::Vector3d jitter = (k * sp) * Normal3(&rng_);
        if (c.ground) jitter = InPlane(jitter, n) + (k * sh) * rng_.Normal() * n;
        if (orientation_tracked_) {
          candidate.angular_velocity += sw * Normal3(&rng_);
          const Eigen::Vector3d wdt = candidate.angular_velocity * dt;
          candidate.position += StepTranslation(wdt, candidate.linear_velocity * dt) + jitter;
          candidate.rotation =
              (QuaternionExp(sr * Normal3(&rng_)) * QuaternionExp(wdt) * candidate.rotation)
                  .normalized();
        } else {
          candidate.position += candidate.linear_velocity * dt + jitter;
        }
      }
      ok = InPsi(candidate, c);
      if (dt <= 0.0) break;  // nothing to redraw
    }
    particles_[i] = candidate;
    // A draw from the truncated transition carries the truncation's normalising constant,
    // the probability of staying in psi, estimated as 1 / draws needed (without it the
    // bounds act as reflecting walls: the accepted velocity noise near a bound points
    // inward, and a constant-velocity particle keeps it).
    if (ok) {
      (*truncation_log_weight)[i] = -std::log(static_cast<double>(attempts));
    } else {
      (*truncation_log_weight)[i] = log_violation;
      ++violations;
    }
  }
  stats_.last_violation_share =
      particles_.empty() ? 0.0 : static_cast<double>(violations) / particles_.size();
}

void BearingOnlyTracker::HoldOnRay(const BotObservation& o) {
  // Before the velocities are seated the particles keep their initial camera depth on the
  // current ray (the object's depth is all they carry yet).
  const Rigid3d world_from_cam = o.cam_from_world.Inverse();
  const Eigen::Vector3d ray = world_from_cam.rotation * o.xy.homogeneous();
  const Rigid3d init_cam_from_world = init_world_from_cam_.Inverse();
  for (BotParticle& p : particles_) {
    const double z = std::max((init_cam_from_world * p.init_position).z(), options_.min_depth);
    p.position = world_from_cam.translation + z * ray;
  }
}

void BearingOnlyTracker::SeatVelocities(const BotObservation& o, const StepCues& c) {
  // Particle i was at p1 = c1 + z1 r1 at initialisation; the new bearing puts it at
  // p2 = c2 + z r2 with a free depth z, i.e. velocity v(z) = (p2 - p1) / dt. Its weight is the
  // marginal likelihood of the two bearings over the velocity prior,
  //   integral prior(v(z)) z^2 dz   (z^2: volume per depth and image area at p2),
  // evaluated on kSeatCells cells of the depths whose speed is in [s_min, s_max], and z is
  // drawn from the same integrand. Prior: uniform in the shell of speeds; with the
  // ground-plane cue uniform in the annulus of horizontal speeds, times a Gaussian on the
  // height change over dt whose sigma is the height tolerance and the bearing noise at both
  // ends (a far particle's crossing with its own horizontal plane is too sensitive to the
  // bearing noise to be taken exactly).
  const double dt = static_cast<double>(o.utime - init_utime_) * kUsToS;
  const Rigid3d world_from_cam = o.cam_from_world.Inverse();
  const Eigen::Vector3d c2 = world_from_cam.translation;
  const Eigen::Vector3d r2 = world_from_cam.rotation * o.xy.homogeneous();
  const double s_min = options_.init_speed_min, s_max = options_.init_speed_max;
  const double log_violation = std::log(options_.violation_weight);
  const double sigma_px = o.bearing_sigma_px > 0.0 ? o.bearing_sigma_px : options_.bearing_sigma_px;
  const double eta = sigma_px / o.focal_px;
  const Rigid3d init_cam_from_world = init_world_from_cam_.Inverse();
  double z_lo = options_.min_depth, z_hi = std::numeric_limits<double>::infinity();
  if (c.depth) {
    z_lo = std::max(z_lo, c.z_min);
    z_hi = std::min(z_hi, c.z_max);
  }
  const Eigen::Vector3d n = c.plane.normal;
  int violations = 0;
  for (BotParticle& p : particles_) {
    const Eigen::Vector3d p1 = p.init_position;
    const double z1 = std::max(init_cam_from_world.translation.z() +
                                   init_cam_from_world.rotation.toRotationMatrix().row(2).dot(p1),
                               options_.min_depth);
    // Depths where |v| <= s_max (a superset in the plane mode), minus |v| < s_min (3D).
    const Eigen::Vector3d a = c2 - p1;
    const double A = r2.squaredNorm(), B = a.dot(r2), C = a.squaredNorm();
    std::vector<std::pair<double, double>> segments;
    const double outer = B * B - A * (C - s_max * s_max * dt * dt);
    if (outer > 0.0) {
      const double lo = (-B - std::sqrt(outer)) / A, hi = (-B + std::sqrt(outer)) / A;
      const double inner =
          (s_min > 0.0 && !c.ground) ? B * B - A * (C - s_min * s_min * dt * dt) : -1.0;
      if (inner > 0.0) {
        segments.push_back({lo, (-B - std::sqrt(inner)) / A});
        segments.push_back({(-B + std::sqrt(inner)) / A, hi});
      } else {
        segments.push_back({lo, hi});
      }
    }
    double length = 0.0;
    for (auto& seg : segments) {
      seg.first = std::max(seg.first, z_lo);
      seg.second = std::min(seg.second, z_hi);
      if (seg.second > seg.first) length += seg.second - seg.first;
    }
    bool feasible = false;
    double z = 0.0, log_w = 0.0;
    if (length > 0.0) {
      double g[kSeatCells];
      double z_at[kSeatCells];
      double total = 0.0;
      const double cell = length / kSeatCells;
      for (int k = 0; k < kSeatCells; ++k) {
        double u = (k + 0.5) * cell;
        double zk = z_lo;
        for (const auto& seg : segments) {
          if (seg.second <= seg.first) continue;
          if (u <= seg.second - seg.first) {
            zk = seg.first + u;
            break;
          }
          u -= seg.second - seg.first;
        }
        const Eigen::Vector3d v = (a + zk * r2) / dt;
        double density = 0.0;
        if (c.ground) {
          const double v_n = n.dot(v);
          const double speed = (v - v_n * n).norm();
          if (speed >= s_min && speed <= s_max) {
            const double sigma_h = std::sqrt(c.height_tolerance * c.height_tolerance +
                                             eta * eta * (z1 * z1 + zk * zk)) /
                                   dt;
            density = std::exp(-0.5 * v_n * v_n / (sigma_h * sigma_h)) / sigma_h;
          }
        } else {
          density = 1.0;  // the segments already hold the speeds in [s_min, s_max]
        }
        z_at[k] = zk;
        g[k] = zk * zk * density;
        total += g[k];
      }
      if (total > 0.0) {
        feasible = true;
        log_w = std::log(total * cell);
        double u = rng_.Uniform() * total;
        int k = 0;
        while (k < kSeatCells - 1 && u > g[k]) u -= g[k++];
        z = std::max(z_at[k] + (rng_.Uniform() - 0.5) * cell, z_lo);
      }
    }
    if (!feasible) z = std::clamp(-B / A, z_lo, std::max(z_lo, std::min(z_hi, z_lo + 1e3)));
    p.position = c2 + z * r2;
    Eigen::Vector3d v = (p.position - p1) / dt;
    if (c.has_plane) p.ground_height = c.plane.Height(p.position);
    if (c.ground) v = InPlane(v, n);
    if (!feasible) {
      // No velocity within the speed prior carries this particle onto the bearing.
      const double speed = v.norm();
      if (speed > s_max && speed > 0.0) v *= s_max / speed;
    }
    p.linear_velocity = v;
    p.angular_velocity.setZero();
    const bool in_psi = InPsi(p, c);
    p.log_weight += (feasible ? log_w : 2.0 * log_violation) + (in_psi ? 0.0 : log_violation);
    violations += (feasible && in_psi) ? 0 : 1;
  }
  stats_.last_violation_share =
      particles_.empty() ? 0.0 : static_cast<double>(violations) / particles_.size();
  seated_ = true;
}

bool BearingOnlyTracker::WeightByBearing(const BotObservation& o,
                                         const std::vector<double>& truncation_log_weight) {
  const double sigma_px = o.bearing_sigma_px > 0.0 ? o.bearing_sigma_px : options_.bearing_sigma_px;
  const double eta = sigma_px / o.focal_px;
  const double inv_two_eta2 = 1.0 / (2.0 * eta * eta);
  const Eigen::Matrix3d R = o.cam_from_world.RotationMatrix();
  const Eigen::Vector3d t = o.cam_from_world.translation;
  std::vector<double> r2(particles_.size());
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < particles_.size(); ++i) {
    const Eigen::Vector3d pc = R * particles_[i].position + t;
    if (pc.z() < options_.min_depth) {
      r2[i] = std::numeric_limits<double>::infinity();
      continue;
    }
    r2[i] = (o.xy - pc.head<2>() / pc.z()).squaredNorm();
    best = std::min(best, r2[i]);
  }
  const double lost = options_.lost_residual_px / o.focal_px;
  if (!(best <= lost * lost)) {
    // The bearing is far from every particle (a jump of the reference point, a wrong
    // association, or a diverged filter): keep each particle's depth, move it onto the ray.
    const Rigid3d world_from_cam = o.cam_from_world.Inverse();
    const Eigen::Vector3d ray = world_from_cam.rotation * o.xy.homogeneous();
    for (BotParticle& p : particles_) {
      const double z = std::max(std::abs((R * p.position + t).z()), options_.min_depth);
      p.position = world_from_cam.translation + z * ray;
      if (plane_) p.ground_height = plane_->Height(p.position);
      p.log_weight = 0.0;
    }
    ++stats_.recoveries;
    MBSLAM_LOG(DEBUG) << "object " << object_id_ << ": bearing " << std::sqrt(best) * o.focal_px
                      << " px from every particle, particles moved onto the ray";
    return false;
  }
  for (size_t i = 0; i < particles_.size(); ++i) {
    BotParticle& p = particles_[i];
    p.log_weight += std::isfinite(r2[i]) ? -r2[i] * inv_two_eta2 : kUnmeasurableLogWeight;
    p.log_weight += truncation_log_weight[i];
  }
  return true;
}

bool BearingOnlyTracker::SfmUsable(const BotObservation& o) const {
  if (!options_.cues.sfm_feedback || !o.sfm || !seated_ || sfm_history_.empty()) return false;
  if (sfm_history_.back().map_id != o.sfm->map_id || o.utime <= sfm_history_.back().utime) {
    return false;
  }
  return (o.sfm->cam_from_obj * o.sfm->reference_in_obj).z() > 0.0;
}

void BearingOnlyTracker::SfmStep(const BotObservation& o, double dt, const StepCues& c,
                                 std::vector<double>* truncation_log_weight) {
  // Given its scale s_i, a particle's positions are measured by the reconstruction,
  // z_i(t) = world_from_cam * (s_i q(t)) with q the reference point in the camera in object
  // units (eq. 6.3): a linear-Gaussian constant-velocity model per particle, run as a
  // Kalman filter (per axis, the three axes share one 2x2 covariance). Its innovation
  // likelihood weights the particle -- the distance between the motion model's prediction
  // and the SfM-implied position -- and its update moves the particle with the SfM-implied
  // motion (eq. 6.4, with the Kalman gain). The likelihood is that of the observed q, so
  // it carries the Jacobian s^3 of z = s q.
  truncation_log_weight->assign(particles_.size(), 0.0);
  const double log_violation = std::log(options_.violation_weight);
  const Eigen::Vector3d q = o.sfm->cam_from_obj * o.sfm->reference_in_obj;
  const Rigid3d world_from_cam = o.cam_from_world.Inverse();
  const double qa2 = options_.accel_sigma * options_.accel_sigma;
  const double qp2 = options_.position_sigma * options_.position_sigma;
  const double ratio2 = options_.sfm_sigma_ratio * options_.sfm_sigma_ratio;
  const double scale_step = options_.sfm_scale_sigma * std::sqrt(dt);
  const Eigen::Vector3d n = c.plane.normal;
  const std::vector<double> noise_scale = NoiseScales();
  int violations = 0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    BotParticle& p = particles_[i];
    if (!(p.sfm_scale > 0.0)) continue;
    const double k2 = noise_scale[i] * noise_scale[i];
    if (scale_step > 0.0) p.sfm_scale *= std::exp(scale_step * rng_.Normal());
    const double s = p.sfm_scale;
    // Predict.
    Eigen::Vector3d position = p.position + p.linear_velocity * dt;
    const double pp =
        p.kf_pp + 2.0 * dt * p.kf_pv + dt * dt * p.kf_vv + k2 * (qa2 * dt * dt * dt / 3.0 + qp2 * dt);
    const double pv = p.kf_pv + dt * p.kf_vv + 0.5 * k2 * qa2 * dt * dt;
    const double vv = p.kf_vv + k2 * qa2 * dt;
    // Update with the SfM-implied position.
    const Eigen::Vector3d measured = world_from_cam * (s * q);
    const double r = ratio2 * (s * q.z()) * (s * q.z());
    const double S = pp + r;
    const Eigen::Vector3d y = measured - position;
    p.log_weight += -0.5 * y.squaredNorm() / S - 1.5 * std::log(S) + 3.0 * std::log(s);
    const double kp = pp / S, kv = pv / S;
    position += kp * y;
    p.linear_velocity += kv * y;
    p.kf_pp = (1.0 - kp) * pp;
    p.kf_pv = (1.0 - kp) * pv;
    p.kf_vv = vv - kv * pv;
    if (c.ground) {
      // The ground plane keeps the height and the horizontal motion.
      position -= (c.plane.Height(position) - p.ground_height) * n;
      p.linear_velocity = InPlane(p.linear_velocity, n);
    }
    p.position = position;
    if (!InPsi(p, c)) {
      (*truncation_log_weight)[i] = log_violation;
      ++violations;
    }
  }
  stats_.last_violation_share =
      particles_.empty() ? 0.0 : static_cast<double>(violations) / particles_.size();
}

void BearingOnlyTracker::RecordSfm(const BotObservation& o) {
  if (!options_.cues.sfm_feedback || !o.sfm) return;
  const Eigen::Vector3d q = o.sfm->cam_from_obj * o.sfm->reference_in_obj;
  if (!(q.z() > 0.0)) return;
  const bool new_map = sfm_history_.empty() || sfm_history_.back().map_id != o.sfm->map_id;
  if (new_map) sfm_history_.clear();  // a new reconstruction: its scale is unrelated
  SfmState now;
  now.map_id = o.sfm->map_id;
  now.utime = o.utime;
  now.world_from_cam = o.cam_from_world.Inverse();
  now.reference_in_cam = q;
  now.world_from_obj_rotation =
      (now.world_from_cam.rotation * o.sfm->cam_from_obj.rotation).normalized();
  // The reconstruction's angular velocity over at least the baseline (closer images give
  // mostly its noise).
  const SfmState* ref = nullptr;
  for (auto it = sfm_history_.rbegin(); it != sfm_history_.rend(); ++it) {
    if (it->utime < o.utime && o.utime - it->utime >= options_.sfm_velocity_baseline_us) {
      ref = &*it;
      break;
    }
  }
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  if (ref != nullptr) {
    const double dt = static_cast<double>(o.utime - ref->utime) * kUsToS;
    w = LogSO3((now.world_from_obj_rotation * ref->world_from_obj_rotation.conjugate())
                   .toRotationMatrix()) /
        dt;
  }
  const Eigen::Matrix3d R_cw = o.cam_from_world.RotationMatrix();
  const Eigen::Vector3d t_cw = o.cam_from_world.translation;
  const double velocity_var = options_.accel_sigma * options_.accel_sigma * 1.0;  // 1 s of it
  const std::vector<double> noise_scale = NoiseScales();
  for (size_t i = 0; i < particles_.size(); ++i) {
    BotParticle& p = particles_[i];
    p.rotation = now.world_from_obj_rotation;
    if (ref != nullptr) p.angular_velocity = w;
    if (!new_map && p.sfm_scale > 0.0) continue;
    // Its scale from its depth: s_i = d_i / d_SfM; the Kalman filter starts from the
    // particle's state.
    const double z = R_cw.row(2).dot(p.position) + t_cw.z();
    if (z <= options_.min_depth) continue;
    p.sfm_scale = z / q.z();
    p.kf_pp = options_.sfm_sigma_ratio * options_.sfm_sigma_ratio * z * z;
    p.kf_pv = 0.0;
    p.kf_vv = velocity_var * noise_scale[i] * noise_scale[i];
  }
  orientation_tracked_ = true;
  sfm_history_.push_back(now);
  while (sfm_history_.size() > 2 &&
         o.utime - sfm_history_[1].utime >= options_.sfm_velocity_baseline_us) {
    sfm_history_.pop_front();
  }
}

bool BearingOnlyTracker::NormalizeAndResample() {
  const size_t n = particles_.size();
  if (n == 0) return false;
  double max_log = -std::numeric_limits<double>::infinity();
  for (const BotParticle& p : particles_) max_log = std::max(max_log, p.log_weight);
  std::vector<double> w(n);
  double sum = 0.0;
  for (size_t i = 0; i < n; ++i) {
    w[i] = std::exp(particles_[i].log_weight - max_log);
    sum += w[i];
  }
  double sum_sq = 0.0;
  for (size_t i = 0; i < n; ++i) {
    w[i] /= sum;
    sum_sq += w[i] * w[i];
    particles_[i].log_weight = w[i] > 0.0 ? std::log(w[i]) : -745.0;
  }
  const double ess = 1.0 / sum_sq;
  stats_.last_ess = ess;
  if (ess >= options_.resample_ess_ratio * static_cast<double>(n)) return false;

  // Systematic resampling: one uniform offset, n equally spaced positions on the CDF.
  std::vector<BotParticle> next;
  next.reserve(n);
  const double step = 1.0 / static_cast<double>(n);
  double u = rng_.Uniform() * step;
  double cdf = w[0];
  size_t j = 0;
  for (size_t k = 0; k < n; ++k) {
    while (u > cdf && j + 1 < n) cdf += w[++j];
    next.push_back(particles_[j]);
    u += step;
  }
  const double log_uniform = -std::log(static_cast<double>(n));
  for (BotParticle& p : next) p.log_weight = log_uniform;
  particles_.swap(next);
  ++stats_.resamplings;
  return true;
}

void BearingOnlyTracker::RegularizeDepths(const StepCues& cues) {
  // Liu-West kernel smoothing of (log depth, velocity) with their empirical covariance:
  // x' = a x + (1 - a) mean + h L e, a = sqrt(1 - h^2), L L^T = covariance. Mean and
  // covariance are kept (so is the depth-velocity correlation of the one-parameter family
  // the bearings cannot tell apart); duplicates of a few survivors spread again.
  const size_t n = particles_.size();
  if (options_.depth_regularization <= 0.0 || n < 8 || !cues.has_camera) return;
  using Vector4 = Eigen::Matrix<double, 4, 1>;
  using Matrix4 = Eigen::Matrix<double, 4, 4>;
  std::vector<Vector4> x(n);
  Vector4 mean = Vector4::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double z = cues.Depth(particles_[i].position);
    if (!(z > 0.0)) return;
    x[i] << std::log(z), particles_[i].linear_velocity;
    mean += x[i];
  }
  mean /= static_cast<double>(n);  // weights are uniform right after resampling
  Matrix4 cov = Matrix4::Zero();
  for (const Vector4& xi : x) cov += (xi - mean) * (xi - mean).transpose();
  cov /= static_cast<double>(n);
  Eigen::SelfAdjointEigenSolver<Matrix4> eig(cov);
  if (eig.info() != Eigen::Success) return;
  const Matrix4 L = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
  // Silverman's bandwidth for four dimensions, scaled by the option.
  const double h = std::min(0.9, options_.depth_regularization * std::pow(4.0 / 6.0, 1.0 / 8.0) *
                                     std::pow(static_cast<double>(n), -1.0 / 8.0));
  const double a = std::sqrt(1.0 - h * h);
  for (size_t i = 0; i < n; ++i) {
    BotParticle& p = particles_[i];
    const Vector4 e(rng_.Normal(), rng_.Normal(), rng_.Normal(), rng_.Normal());
    const Vector4 target = a * x[i] + (1.0 - a) * mean + h * (L * e);
    const double f = std::exp(target[0] - x[i][0]);
    BotParticle moved = p;
    moved.position = cues.center + f * (p.position - cues.center);  // along its viewing ray
    moved.linear_velocity = target.tail<3>();
    if (cues.has_plane) {
      moved.ground_height = cues.plane.Height(moved.position);
      if (cues.ground) moved.linear_velocity = InPlane(moved.linear_velocity, cues.plane.normal);
    }
    moved.sfm_scale *= f;
    if (InPsi(moved, cues)) p = moved;
  }
}

Status BearingOnlyTracker::Update(const BotObservation& o) {
  if (!initialized_) return Status::Error("BearingOnlyTracker::Update before Initialize");
  if (Status s = CheckObservation(o); !s.ok()) {
    ++stats_.rejected_inputs;
    return s.WithContext("BearingOnlyTracker::Update");
  }
  if (o.utime < utime_) {
    ++stats_.rejected_inputs;
    return Status::Error("BearingOnlyTracker::Update: time went backwards (" +
                         std::to_string(o.utime) + " < " + std::to_string(utime_) + ")");
  }
  const double dt = static_cast<double>(o.utime - utime_) * kUsToS;
  RebaseGroundHeights(o.ground_plane);
  const StepCues cues = MakeCues(&o);
  ++stats_.updates;
  if (dt > 0.0) {
    camera_velocity_ = (cues.center - cam_from_world_.Inverse().translation) / dt;
  }
  utime_ = o.utime;
  cam_from_world_ = o.cam_from_world;

  if (!seated_) {
    if (o.utime - init_utime_ < std::max<int64_t>(options_.init_velocity_baseline_us, 1)) {
      HoldOnRay(o);
      return Status::Ok();
    }
    SeatVelocities(o, cues);
    if (NormalizeAndResample()) RegularizeDepths(cues);
    RecordSfm(o);
    return Status::Ok();
  }

  std::vector<double> truncation;
  if (SfmUsable(o)) {
    ++stats_.sfm_steps;
    SfmStep(o, dt, cues, &truncation);
  } else {
    Propagate(dt, cues, &truncation);
  }
  WeightByBearing(o, truncation);
  if (NormalizeAndResample()) RegularizeDepths(cues);
  RecordSfm(o);
  return Status::Ok();
}

Status BearingOnlyTracker::Predict(int64_t utime, const std::optional<GroundPlane>& ground_plane) {
  if (!initialized_) return Status::Error("BearingOnlyTracker::Predict before Initialize");
  if (utime < utime_) {
    ++stats_.rejected_inputs;
    return Status::Error("BearingOnlyTracker::Predict: time went backwards");
  }
  ++stats_.predictions;
  if (!seated_) {  // nothing known about the motion yet
    utime_ = utime;
    return Status::Ok();
  }
  RebaseGroundHeights(ground_plane);
  const StepCues cues = MakeCues(nullptr);
  std::vector<double> truncation;
  Propagate(static_cast<double>(utime - utime_) * kUsToS, cues, &truncation);
  for (size_t i = 0; i < particles_.size(); ++i) particles_[i].log_weight += truncation[i];
  utime_ = utime;
  NormalizeAndResample();
  return Status::Ok();
}

std::vector<int> BearingOnlyTracker::SystematicIndices(int count) const {
  std::vector<int> indices;
  const size_t n = particles_.size();
  if (n == 0 || count <= 0) return indices;
  indices.reserve(static_cast<size_t>(count));
  const double step = 1.0 / count;
  double u = 0.5 * step;
  double cdf = std::exp(particles_[0].log_weight);
  size_t j = 0;
  for (int k = 0; k < count; ++k) {
    while (u > cdf && j + 1 < n) cdf += std::exp(particles_[++j].log_weight);
    indices.push_back(static_cast<int>(j));
    u += step;
  }
  return indices;
}

BotEstimate BearingOnlyTracker::Estimate() const {
  BotEstimate e;
  e.utime = utime_;
  e.valid = initialized_ && !particles_.empty();
  if (!e.valid) return e;
  e.velocity_initialized = seated_;
  e.num_particles = static_cast<int>(particles_.size());
  e.effective_sample_size = stats_.last_ess;

  const Eigen::Matrix3d R = cam_from_world_.RotationMatrix();
  const Eigen::Vector3d t = cam_from_world_.translation;
  Eigen::Vector3d mean_p = Eigen::Vector3d::Zero();
  Vector6d mean_v = Vector6d::Zero();
  double mean_z = 0.0;
  std::vector<double> w(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) {
    const BotParticle& p = particles_[i];
    w[i] = std::exp(p.log_weight);
    mean_p += w[i] * p.position;
    mean_v += w[i] * p.twist();
    mean_z += w[i] * (R.row(2).dot(p.position) + t.z());
  }
  // Mean orientation: the particles share their rotation up to jitter; average the
  // quaternions on one hemisphere.
  Eigen::Quaterniond mean_q = Eigen::Quaterniond::Identity();
  if (orientation_tracked_) {
    const Eigen::Quaterniond q0 = particles_[0].rotation;
    Eigen::Vector4d acc = Eigen::Vector4d::Zero();
    for (size_t i = 0; i < particles_.size(); ++i) {
      Eigen::Vector4d c = particles_[i].rotation.coeffs();
      if (c.dot(q0.coeffs()) < 0.0) c = -c;
      acc += w[i] * c;
    }
    if (acc.norm() > 1e-12) mean_q = Eigen::Quaterniond(acc / acc.norm());
  }
  Matrix6d pose_cov = Matrix6d::Zero();
  Matrix6d vel_cov = Matrix6d::Zero();
  double var_z = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i) {
    const BotParticle& p = particles_[i];
    Vector6d d;
    d.head<3>() = p.position - mean_p;
    if (orientation_tracked_) {
      // Left perturbation of the rotation: 2 vec(q_i q_mean^-1) for the small spread
      // among particles, the full logarithm beyond 0.1 rad.
      Eigen::Quaterniond dq = p.rotation * mean_q.conjugate();
      if (dq.w() < 0.0) dq.coeffs() = -dq.coeffs();
      d.tail<3>() = dq.vec().squaredNorm() < 2.5e-3 ? Eigen::Vector3d(2.0 * dq.vec())
                                                    : LogSO3(dq.toRotationMatrix());
    } else {
      d.tail<3>().setZero();
    }
    pose_cov += w[i] * d * d.transpose();
    const Vector6d dv = p.twist() - mean_v;
    vel_cov += w[i] * dv * dv.transpose();
    const double dz = R.row(2).dot(p.position) + t.z() - mean_z;
    var_z += w[i] * dz * dz;
  }
  if (!orientation_tracked_) {
    pose_cov.bottomRightCorner<3, 3>() = M_PI * M_PI * Eigen::Matrix3d::Identity();
  }
  e.world_from_object = Rigid3d(mean_q, mean_p);
  e.has_orientation = orientation_tracked_;
  e.pose_covariance = pose_cov;
  e.linear_velocity = mean_v.head<3>();
  e.angular_velocity = mean_v.tail<3>();
  e.has_angular_velocity = orientation_tracked_;
  e.velocity_covariance = vel_cov;
  e.depth = mean_z;
  e.depth_sigma = std::sqrt(std::max(var_z, 0.0));
  e.reliable =
      seated_ && mean_z > 0.0 && e.depth_sigma <= options_.reliable_depth_sigma_ratio * mean_z;
  for (int i : SystematicIndices(options_.num_output_samples)) {
    e.particle_samples.push_back(particles_[static_cast<size_t>(i)].position.cast<float>());
  }
  e.relative_scale = RelativeScaleFromSfm();
  return e;
}

std::optional<RelativeScaleEstimate> BearingOnlyTracker::RelativeScaleFromSfm() const {
  if (!initialized_ || sfm_history_.empty()) return std::nullopt;
  double sum_w = 0.0, mean = 0.0;
  for (const BotParticle& p : particles_) {
    if (!(p.sfm_scale > 0.0)) continue;
    const double w = std::exp(p.log_weight);
    sum_w += w;
    mean += w * p.sfm_scale;
  }
  if (!(sum_w > 0.0)) return std::nullopt;
  mean /= sum_w;
  double var = 0.0;
  for (const BotParticle& p : particles_) {
    if (!(p.sfm_scale > 0.0)) continue;
    const double d = p.sfm_scale - mean;
    var += std::exp(p.log_weight) * d * d;
  }
  RelativeScaleEstimate e;
  e.scale = mean;
  e.sigma = std::sqrt(var / sum_w);
  return e;
}

std::vector<PredictedVolume> BearingOnlyTracker::PredictVolumes(const ObjectExtent& extent) const {
  std::vector<PredictedVolume> volumes;
  if (!initialized_ || particles_.empty()) return volumes;
  const PredictedVolumeOptions& vo = options_.volumes;
  const std::vector<int> indices =
      SystematicIndices(std::min<int>(vo.max_samples, static_cast<int>(particles_.size())));
  std::optional<Eigen::Vector3d> up;
  if (plane_) up = plane_->normal;
  std::vector<Eigen::Vector3d> centers(indices.size());
  const int64_t first = vo.include_current ? 0 : vo.step_us;
  for (int64_t h = first; h <= vo.horizon_us; h += vo.step_us) {
    const double tau = static_cast<double>(h) * kUsToS;
    for (size_t k = 0; k < indices.size(); ++k) {
      const BotParticle& p = particles_[static_cast<size_t>(indices[k])];
      // Before the velocities are seated the motion is unknown: the prior speeds apply.
      Eigen::Vector3d step = p.linear_velocity * tau;
      if (orientation_tracked_) step = StepTranslation(p.angular_velocity * tau, step);
      centers[k] = p.position + step;
    }
    PredictedVolume v =
        BoundingVolume(centers, up, extent, vo.probability, 0.5 * vo.accel_margin * tau * tau);
    v.utime = utime_ + h;
    v.horizon_us = h;
    volumes.push_back(v);
    if (vo.step_us <= 0) break;
  }
  return volumes;
}

void BearingOnlyTracker::RescaleWorld(double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor)) return;
  for (BotParticle& p : particles_) {
    p.position *= factor;
    p.init_position *= factor;
    p.linear_velocity *= factor;
    p.ground_height *= factor;
    p.sfm_scale *= factor;
  }
  if (plane_) plane_->Rescale(factor);
  init_world_from_cam_.translation *= factor;
  cam_from_world_.translation *= factor;
  camera_velocity_ *= factor;
  for (SfmState& s : sfm_history_) s.world_from_cam.translation *= factor;
}

}  // namespace mbslam
