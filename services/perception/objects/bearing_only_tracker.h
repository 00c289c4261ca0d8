#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_BEARING_ONLY_TRACKER_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_BEARING_ONLY_TRACKER_H_

// Bearing-only tracking of one moving object with a particle filter (thesis ch. 5), with
// the cues of sec. 5.1.1 / 5.1.3 and the SfM feedback of sec. 6.2.
//
// State of particle i: world_from_particle g_i on SE(3), whose translation is the tracked
// reference point of the object (e.g. the centroid of its feature tracks), and a constant
// velocity twist xi_i = [v; w]. The twist is expressed in world axes at the tracked point
// (v is the point's velocity, w the angular velocity), i.e. in the world frame it is
// Ad([I | p_i]) xi_i; the motion model of eq. 5.1,
//   g_i(t+1) = exp(a^) exp(xi_i^ dt) g_i(t),
// then moves the point by J_l(w dt) v dt and turns the particle about its own point, so an
// angular perturbation does not swing particles about the world origin. Noise: the twist
// takes a random-walk step e ~ N(0, diag(accel_sigma^2, angular_accel_sigma^2) dt) before
// it is applied (white-noise acceleration: frame-rate independent; the twist carried on
// is the one the thesis recovers as log(g(t+1) g(t)^-1) / dt), and a ~ N(0,
// diag(position_sigma^2, rotation_sigma^2) dt) jitters the pose. With depth_relative_noise
// the translational sigmas hold at the cloud's mean camera depth and scale with each
// particle's depth, so that bearings alone (whose jitter is sigma / depth) do not tell
// depth hypotheses apart; only the camera's parallax and the cues do.
//
// Measurement (eq. 5.2): z_i = project(cam_from_world * translation(g_i)) in normalised
// image coordinates; log-weight -|z - z_i|^2 / (2 eta^2), eta = bearing_sigma_px / focal.
// Systematic resampling when the effective sample size falls below a share of N, then a
// regularisation (Liu-West kernel smoothing with shrinkage) of each particle's log-depth
// along its viewing ray and its velocity, with their empirical covariance: mean and
// covariance are kept, duplicates of a few survivors spread again, and the cloud can follow
// evidence that arrives later (without it, particles near the truth that a wide prior
// down-weighted early are lost for good, and the genealogy collapses onto a few ancestors
// in the directions the bearings cannot observe).
//
// Initialisation (sec. 5.1.2): depths uniform in [d_min, d_max] along the viewing ray (the
// depth bound when given), or N(d, sigma^2) around the mapped depth of a previously static
// object. Velocities uniform over all directions with speeds in [s_min, s_max] (uniform
// density in that spherical shell, or in the annulus of the ground plane with the
// ground-plane cue) are drawn at once for the estimate, and then *seated* at the first
// bearing at least init_velocity_baseline_us later: instead of leaving almost every blind
// velocity draw to die (the bearing fixes two velocity components within a few cm/s), each
// particle draws its velocity among those that carry it onto the new bearing, with the
// importance weight of that prior (its integral along the line of such velocities, times
// the volume factor z^2 of the new depth z).
//
// Cues (each switchable, BotCues) define the set psi of admissible states; the motion
// model is sampled truncated to psi by bounded rejection (max_rejection_tries redraws),
// weighted by the estimated probability of staying in psi (1 / draws needed: the truncated
// density's normalising constant, which keeps the bounds from acting as reflecting walls),
// and a particle that still violates psi gets its weight multiplied by violation_weight:
//   depth bound   camera depth within the caller's [min, max] along the ray (from the
//                 static map's depths in the object's frustum);
//   ground plane  velocity parallel to the ground plane, height above it constant within
//                 ground_height_tolerance, the tracked point not below the ground;
//   size bound    the object's tracks, placed at the particle's depth, neither below the
//                 ground (below_ground_tolerance) nor floating above it (its lowest track at
//                 most max_ground_clearance up), nor taller than max_object_height;
//   SfM feedback  (eq. 6.3-6.4) with the object's own reconstruction (cam_from_obj up to
//                 a scale and the reference point in it): particle i's depth d_i fixes its
//                 scale s_i = d_i / d_SfM, and with it every position the reconstruction
//                 implies, t_i = R_cw^T (s_i t_co - t_cw). These act as a secondary
//                 observation: each particle runs a constant-velocity Kalman filter on its
//                 SfM-implied positions (the particle is then (s_i, its Kalman state): a
//                 Rao-Blackwellised filter), whose innovation -- the distance between the
//                 motion model's prediction and t_i -- weights it, and whose update moves it
//                 with the SfM-implied motion (eq. 6.4 with the Kalman gain). A scale whose
//                 trajectory is not a constant-velocity motion on the ground (the camera
//                 accelerates, bobs, turns) loses weight; the rotation comes from R_cw^T R_co.
//
// Units: "units" are world units (metres once the static map is metric). Time is int64 µs.
// Deterministic: the generator is seeded from options.seed and the object id.

#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/config/options.h"
#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/objects/ground_plane.h"
#include "services/perception/objects/object_extent.h"
#include "services/perception/objects/predicted_volume.h"
#include "services/perception/objects/random.h"
#include "services/perception/objects/relative_scale.h"

namespace mbslam {

// The cue set psi (sec. 5.1.1, 6.2); every cue can be switched off (fig. 6.6 ablation).
struct BotCues {
  bool depth_bound = true;   // camera depth within the observation's depth bound
  bool ground_plane = true;  // velocity parallel to the ground, constant height above it
  bool size_bound = true;    // the object's tracks not below the ground, not floating, not too tall
  bool sfm_feedback = true;  // the object's own reconstruction fixes each particle's motion

  bool Check() const { return true; }
  template <typename V>
  void VisitFields(V& v) {
    v("depth_bound", &depth_bound, "camera depth within the depth bound from the static map");
    v("ground_plane", &ground_plane, "velocity parallel to the ground, constant height");
    v("size_bound", &size_bound, "tracks not below the ground, not floating, not too tall");
    v("sfm_feedback", &sfm_feedback, "the object's reconstruction fixes each particle's motion");
  }
};

struct BearingOnlyTrackerOptions {
  int num_particles = 1000;  // particles per object (count)
  // Initialisation (sec. 5.1.2).
  double init_depth_min = 1.0;   // depth range along the ray without a depth bound (units)
  double init_depth_max = 60.0;  // (units)
  double init_speed_min = 0.0;   // velocity prior: uniform, speeds in [min, max] (units/s)
  double init_speed_max = 15.0;  // (units/s)
  int64_t init_velocity_baseline_us =
      300000;  // velocities are seated at the first bearing this much later (µs)
  double static_depth_sigma_ratio =
      0.05;  // previously static object: depth sigma / depth when not given
  // Motion model (eq. 5.1).
  double accel_sigma = 0.5;          // white-noise linear acceleration (units/s^1.5)
  double angular_accel_sigma = 0.1;  // white-noise angular acceleration (rad/s^1.5)
  double position_sigma = 0.03;      // pose jitter, translation (units/s^0.5)
  double rotation_sigma = 0.01;      // pose jitter, rotation (rad/s^0.5)
  // The translational noises (accel_sigma, position_sigma, ground_height_sigma and the SfM
  // filter's) hold at the cloud's mean camera depth and scale with each particle's depth:
  // every depth hypothesis then predicts the same bearing jitter, so the smoothness of the
  // bearings does not favour far hypotheses (with noise in units, a farther particle's
  // bearing jitters less and the filter drifts to the far edge of its cues).
  bool depth_relative_noise = true;
  // Measurement (eq. 5.2).
  double bearing_sigma_px = 2.0;    // eta: bearing noise of the reference point (px)
  double min_depth = 0.2;           // particles nearer than this to the camera are invalid (units)
  double resample_ess_ratio = 0.5;  // resample when ESS < ratio * N (0, 1]
  double depth_regularization = 1.0;  // after resampling, (log depth, velocity) kernel of this x
                                      // Silverman's bandwidth (0 = off)
  double lost_residual_px =
      40.0;  // no particle this close to the bearing: particles move onto the ray (px)
  // Truncated sampling (sec. 5.1.3).
  int max_rejection_tries = 10;    // redraws to satisfy the cue set psi (count)
  double violation_weight = 1e-3;  // weight factor of a particle still outside psi (0, 1]
  // Cues.
  BotCues cues;
  double ground_height_tolerance =
      0.15;  // ground plane: height change of the tracked point allowed (units)
  double ground_height_sigma =
      0.02;  // ground plane: vertical jitter of the tracked point (units/s^0.5)
  double below_ground_tolerance = 0.15;  // tracks may appear this far below the ground (units)
  double max_ground_clearance =
      0.6;  // size bound: lowest track at most this high above the ground (units)
  double max_object_height = 4.0;       // size bound: object height at most (units)
  double size_bound_percentile = 0.05;  // robust lowest / highest track: this percentile [0, 0.5)
  int size_bound_min_tracks = 3;        // fewer tracks: no size bound in that image (count)
  double sfm_sigma_ratio = 0.01;        // SfM position noise, fraction of the depth (ratio)
  double sfm_scale_sigma = 0.01;  // random walk of each particle's log scale under SfM (1/s^0.5)
  int64_t sfm_velocity_baseline_us = 300000;  // SfM angular velocity over at least this time (µs)
  // Outputs.
  int num_output_samples = 100;  // particle positions in the estimate (count)
  double reliable_depth_sigma_ratio =
      0.2;  // estimate reliable when depth sigma / depth below (ratio)
  PredictedVolumeOptions volumes;
  int64_t seed = 0;  // mixed with the object id (deterministic)

  bool Check() const {
    MBSLAM_CHECK_OPTION_GE(num_particles, 10);
    MBSLAM_CHECK_OPTION_GT(init_depth_min, 0.0);
    MBSLAM_CHECK_OPTION_GT(init_depth_max, init_depth_min);
    MBSLAM_CHECK_OPTION_GE(init_speed_min, 0.0);
    MBSLAM_CHECK_OPTION_GT(init_speed_max, init_speed_min);
    MBSLAM_CHECK_OPTION_GE(init_velocity_baseline_us, 0);
    MBSLAM_CHECK_OPTION_GT(static_depth_sigma_ratio, 0.0);
    MBSLAM_CHECK_OPTION_GE(accel_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(angular_accel_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(position_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(rotation_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GT(bearing_sigma_px, 0.0);
    MBSLAM_CHECK_OPTION_GT(min_depth, 0.0);
    MBSLAM_CHECK_OPTION(resample_ess_ratio > 0.0 && resample_ess_ratio <= 1.0);
    MBSLAM_CHECK_OPTION(depth_regularization >= 0.0 && depth_regularization < 3.0);
    MBSLAM_CHECK_OPTION_GT(lost_residual_px, 0.0);
    MBSLAM_CHECK_OPTION_GE(max_rejection_tries, 1);
    MBSLAM_CHECK_OPTION(violation_weight > 0.0 && violation_weight <= 1.0);
    MBSLAM_CHECK_OPTION_SECTION(cues);
    MBSLAM_CHECK_OPTION_GT(ground_height_tolerance, 0.0);
    MBSLAM_CHECK_OPTION_GE(ground_height_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(below_ground_tolerance, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_ground_clearance, 0.0);
    MBSLAM_CHECK_OPTION_GT(max_object_height, 0.0);
    MBSLAM_CHECK_OPTION(size_bound_percentile >= 0.0 && size_bound_percentile < 0.5);
    MBSLAM_CHECK_OPTION_GE(size_bound_min_tracks, 1);
    MBSLAM_CHECK_OPTION_GT(sfm_sigma_ratio, 0.0);
    MBSLAM_CHECK_OPTION_GE(sfm_scale_sigma, 0.0);
    MBSLAM_CHECK_OPTION_GE(sfm_velocity_baseline_us, 0);
    MBSLAM_CHECK_OPTION_GE(num_output_samples, 0);
    MBSLAM_CHECK_OPTION_GT(reliable_depth_sigma_ratio, 0.0);
    MBSLAM_CHECK_OPTION_SECTION(volumes);
    return true;
  }
  template <typename V>
  void VisitFields(V& v) {
    v("num_particles", &num_particles, "particles per object (count)");
    v("init_depth_min", &init_depth_min, "depth range along the ray without a depth bound (units)");
    v("init_depth_max", &init_depth_max, "(units)");
    v("init_speed_min", &init_speed_min, "velocity prior: uniform, speeds in [min, max] (units/s)");
    v("init_speed_max", &init_speed_max, "(units/s)");
    v("init_velocity_baseline_us", &init_velocity_baseline_us,
      "velocities seated at the first bearing this much later (us)");
    v("static_depth_sigma_ratio", &static_depth_sigma_ratio,
      "previously static object: depth sigma / depth when not given");
    v("accel_sigma", &accel_sigma, "white-noise linear acceleration (units/s^1.5)");
    v("angular_accel_sigma", &angular_accel_sigma, "white-noise angular acceleration (rad/s^1.5)");
    v("position_sigma", &position_sigma, "pose jitter, translation (units/s^0.5)");
    v("rotation_sigma", &rotation_sigma, "pose jitter, rotation (rad/s^0.5)");
    v("depth_relative_noise", &depth_relative_noise,
      "translational noises hold at the cloud's mean depth, scale with each particle's depth");
    v("bearing_sigma_px", &bearing_sigma_px, "eta: bearing noise of the reference point (px)");
    v("min_depth", &min_depth, "particles nearer than this are invalid (units)");
    v("resample_ess_ratio", &resample_ess_ratio, "resample when ESS < ratio * N (0, 1]");
    v("depth_regularization", &depth_regularization,
      "(log depth, velocity) kernel after resampling, x Silverman's bandwidth (0 = off)");
    v("lost_residual_px", &lost_residual_px,
      "no particle this close: particles move onto the ray (px)");
    v("max_rejection_tries", &max_rejection_tries, "redraws to satisfy the cue set (count)");
    v("violation_weight", &violation_weight,
      "weight factor of a particle outside the cue set (0, 1]");
    v("cues", &cues, "cue set psi");
    v("ground_height_tolerance", &ground_height_tolerance,
      "height change allowed on the ground plane (units)");
    v("ground_height_sigma", &ground_height_sigma,
      "vertical jitter on the ground plane (units/s^0.5)");
    v("below_ground_tolerance", &below_ground_tolerance,
      "tracks may appear this far below the ground (units)");
    v("max_ground_clearance", &max_ground_clearance,
      "lowest track at most this high above the ground (units)");
    v("max_object_height", &max_object_height, "object height at most (units)");
    v("size_bound_percentile", &size_bound_percentile,
      "robust lowest / highest track percentile [0, 0.5)");
    v("size_bound_min_tracks", &size_bound_min_tracks, "fewer tracks: no size bound (count)");
    v("sfm_sigma_ratio", &sfm_sigma_ratio, "SfM position noise, fraction of the depth");
    v("sfm_scale_sigma", &sfm_scale_sigma,
      "random walk of each particle's log scale under SfM (1/s^0.5)");
    v("sfm_velocity_baseline_us", &sfm_velocity_baseline_us,
      "SfM angular velocity over at least this time (us)");
    v("num_output_samples", &num_output_samples, "particle positions in the estimate (count)");
    v("reliable_depth_sigma_ratio", &reliable_depth_sigma_ratio,
      "reliable when depth sigma / depth below");
    v("volumes", &volumes, "predicted volumes");
    v("seed", &seed, "mixed with the object id");
  }
};

// Depths along the optical axis (camera z) that the object may have (units).
struct DepthRange {
  double min = 0.0;
  double max = std::numeric_limits<double>::infinity();
};

// The object's own reconstruction in one image (its SLAM, its own unknown scale).
struct SfmObservation {
  int64_t map_id = 0;    // identifies the reconstruction; a new id is a new, unrelated scale
  Rigid3d cam_from_obj;  // object SLAM pose of this image (object map units)
  // The tracked reference point in the object's frame (object map units); its projection
  // should be (close to) the observation's bearing.
  Eigen::Vector3d reference_in_obj = Eigen::Vector3d::Zero();
};

// One image's evidence about one object.
struct BotObservation {
  int64_t utime = 0;       // image time (µs)
  Rigid3d cam_from_world;  // static SLAM pose of this image
  double focal_px = 0.0;   // focal length: pixel sigmas -> normalised (px)
  Eigen::Vector2d xy =
      Eigen::Vector2d::Zero();    // bearing of the reference point (normalised, undistorted)
  double bearing_sigma_px = 0.0;  // > 0 overrides options.bearing_sigma_px (px)
  std::vector<Eigen::Vector2d> track_xy;  // the object's tracks (normalised): size bound, extent
  std::optional<DepthRange> depth_bound;  // static map depths along this ray (depth-bound cue)
  std::optional<GroundPlane>
      ground_plane;                   // static map's ground (ground-plane and size-bound cues)
  std::optional<SfmObservation> sfm;  // the object's reconstruction (SfM feedback)
};

struct BotParticle {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();            // tracked point, world (units)
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();  // world_from_particle rotation
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();     // v, world axes (units/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();    // w, world axes (rad/s)
  double log_weight = 0.0;                                       // normalised: sum of exp = 1
  double ground_height = 0.0;  // height above the ground kept by the ground-plane cue (units)
  double sfm_scale = 0.0;      // s_i = d_i / d_SfM (world units per object map unit), 0 if none
  // Under SfM feedback: per-axis covariance of (position, velocity) of the particle's
  // Kalman filter on the SfM-implied positions (units^2, units^2/s, units^2/s^2).
  double kf_pp = 0.0, kf_pv = 0.0, kf_vv = 0.0;
  Eigen::Vector3d init_position = Eigen::Vector3d::Zero();  // at initialisation (velocity seating)

  Rigid3d world_from_particle() const { return Rigid3d(rotation, position); }
  Vector6d twist() const {
    Vector6d xi;
    xi << linear_velocity, angular_velocity;
    return xi;
  }
};

struct BotEstimate {
  int64_t utime = 0;
  bool valid = false;                 // the tracker is initialised
  bool velocity_initialized = false;  // velocities seated (sec. 5.1.2)
  bool reliable = false;              // velocities seated and depth_sigma <= ratio * depth
  Rigid3d world_from_object;          // weighted mean; rotation identity unless has_orientation
  bool has_orientation = false;       // rotation from the object's reconstruction
  Matrix6d pose_covariance = Matrix6d::Zero();  // [t; r]; rotation block pi^2 I when unknown
  Eigen::Vector3d linear_velocity = Eigen::Vector3d::Zero();   // (units/s)
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  // (rad/s)
  bool has_angular_velocity = false;
  Matrix6d velocity_covariance = Matrix6d::Zero();  // [v; w]
  double depth = 0.0;        // mean camera depth of the tracked point, latest image (units)
  double depth_sigma = 0.0;  // (units)
  double effective_sample_size = 0.0;
  int num_particles = 0;
  std::vector<Eigen::Vector3f> particle_samples;        // deterministic weighted subsample (units)
  std::optional<RelativeScaleEstimate> relative_scale;  // from the SfM feedback (sec. 6.1)
};

struct BotStats {
  int64_t updates = 0;
  int64_t predictions = 0;  // steps without a bearing
  int64_t sfm_steps = 0;    // updates that used the object's reconstruction
  int64_t resamplings = 0;
  int64_t recoveries = 0;             // bearing far from every particle: moved onto the ray
  int64_t rejected_inputs = 0;        // observations refused (bad input, time backwards)
  double last_violation_share = 0.0;  // particles outside psi after the last step [0, 1]
  double last_ess = 0.0;
};

class BearingOnlyTracker {
 public:
  // Invalid options are reported by every call (Initialize / Update return the error).
  BearingOnlyTracker(const BearingOnlyTrackerOptions& options, int64_t object_id);

  // First bearing of a newly moving object: depths uniform along the ray (sec. 5.1.2).
  Status Initialize(const BotObservation& observation);
  // A previously static object: depths N(d, sigma^2) around the mapped depth d of
  // `point_in_world` (sigma = static_depth_sigma_ratio * d when depth_sigma <= 0).
  Status InitializeFromPoint(const BotObservation& observation,
                             const Eigen::Vector3d& point_in_world, double depth_sigma = 0.0);

  // Predict to observation.utime (truncated to the cue set), weight by the bearing and the
  // SfM feedback, resample. utime must not go backwards (equal: no motion).
  Status Update(const BotObservation& observation);
  // Predict without a bearing (object not seen in this image).
  Status Predict(int64_t utime, const std::optional<GroundPlane>& ground_plane = std::nullopt);

  // The estimate at the latest time, depths w.r.t. the latest observation's camera.
  BotEstimate Estimate() const;
  // Current (horizon 0 when options.volumes.include_current) and predicted volumes.
  std::vector<PredictedVolume> PredictVolumes(const ObjectExtent& extent) const;
  // s = d_BOT / d_SfM over the particles (mean and spread of s_i), once SfM was given.
  std::optional<RelativeScaleEstimate> RelativeScaleFromSfm() const;

  // The world's units were multiplied by `factor` (e.g. the map became metric).
  void RescaleWorld(double factor);
  void Reset();

  bool initialized() const { return initialized_; }
  bool velocity_initialized() const { return seated_; }
  int64_t utime() const { return utime_; }
  int64_t object_id() const { return object_id_; }
  const std::vector<BotParticle>& particles() const { return particles_; }
  const BotStats& stats() const { return stats_; }
  const BearingOnlyTrackerOptions& options() const { return options_; }

 private:
  struct StepCues;
  // One image of the object's reconstruction.
  struct SfmState {
    int64_t map_id = 0;
    int64_t utime = 0;
    Rigid3d world_from_cam;
    Eigen::Vector3d reference_in_cam = Eigen::Vector3d::Zero();  // object map units
    Eigen::Quaterniond world_from_obj_rotation = Eigen::Quaterniond::Identity();
  };

  Status CheckObservation(const BotObservation& observation) const;
  Status InitializeImpl(const BotObservation& observation, const Eigen::Vector3d* point_in_world,
                        double depth_sigma);
  StepCues MakeCues(const BotObservation* observation) const;
  bool InPsi(const BotParticle& particle, const StepCues& cues) const;
  void DrawInitialVelocity(BotParticle* particle, const StepCues& cues);
  void Propagate(double dt, const StepCues& cues, std::vector<double>* truncation_log_weight);
  void SeatVelocities(const BotObservation& observation, const StepCues& cues);
  void HoldOnRay(const BotObservation& observation);
  // Per particle: its camera depth over the cloud's weighted mean depth (1 when
  // depth_relative_noise is off), for the translational process noise.
  std::vector<double> NoiseScales() const;
  bool WeightByBearing(const BotObservation& observation,
                       const std::vector<double>& truncation_log_weight);
  bool SfmUsable(const BotObservation& observation) const;
  void SfmStep(const BotObservation& observation, double dt, const StepCues& cues,
               std::vector<double>* truncation_log_weight);
  void RecordSfm(const BotObservation& observation);
  void RebaseGroundHeights(const std::optional<GroundPlane>& plane);
  // Returns true when it resampled.
  bool NormalizeAndResample();
  void RegularizeDepths(const StepCues& cues);
  // Deterministic weighted subsample: indices at CDF positions (k + 0.5) / count.
  std::vector<int> SystematicIndices(int count) const;

  BearingOnlyTrackerOptions options_;
  bool options_ok_ = false;
  int64_t object_id_ = 0;
  ParticleRng rng_;
  std::vector<BotParticle> particles_;
  bool initialized_ = false;
  bool seated_ = false;
  bool orientation_tracked_ = false;
  int64_t utime_ = 0;
  int64_t init_utime_ = 0;
  Rigid3d init_world_from_cam_;
  Rigid3d cam_from_world_;
  Eigen::Vector3d camera_velocity_ = Eigen::Vector3d::Zero();  // world (units/s)
  std::optional<GroundPlane> plane_;  // the plane the particles' ground heights refer to
  std::deque<SfmState> sfm_history_;  // recent SfM images of the current reconstruction
  BotStats stats_;
};

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_BEARING_ONLY_TRACKER_H_
