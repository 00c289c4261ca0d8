#ifndef MBSLAM_SERVICES_PERCEPTION_OBJECTS_BOT_SIMULATION_H_
#define MBSLAM_SERVICES_PERCEPTION_OBJECTS_BOT_SIMULATION_H_

// Synthetic scenes for the bearing-only tracker (tests, the cue ablation tool and the
// benchmark; not used by the service). A camera moves forward over a flat ground (z = 0,
// world x forward, y left, z up) between two building facades, either like a car (speed
// changing with the traffic, a few mm of suspension bob) or hand-held by a walking person
// (pace surging with each step, vertical bob, sway and small rotations), and watches a
// box-shaped target that moves at constant velocity on the ground: ahead of the camera in
// the same direction (following: the degenerate case for monocular motion segmentation
// and bearing-only tracking) or across its path (crossing). Every image gives the
// tracker's observation with all the cue inputs a perception core would compute: the
// bearing of the target's reference point (the centroid of its feature points), its
// tracks, the depth bound of the static scene along that ray, the ground plane estimated
// by RANSAC from noisy static points with outliers, and, after a delay, the target's own
// "SfM" (its true pose relative to the camera in an arbitrary scale, with noise).

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"
#include "services/perception/objects/bearing_only_tracker.h"
#include "services/perception/objects/ground_plane.h"
#include "services/perception/objects/object_extent.h"

namespace mbslam {

enum class BotSimCamera { kCar, kHandHeld };
enum class BotSimTarget { kFollowing, kCrossing };

const char* BotSimCameraName(BotSimCamera camera);
const char* BotSimTargetName(BotSimTarget target);

struct BotSimOptions {
  BotSimCamera camera = BotSimCamera::kHandHeld;
  BotSimTarget target = BotSimTarget::kFollowing;
  double wiggle_scale =
      1.0;                  // scales the camera's speed changes, bob, sway, rotations (0 = smooth)
  double fps = 30.0;        // image rate (Hz)
  double duration_s = 3.0;  // sequence length (s)
  double focal_px = 500.0;  // pinhole focal length (px), 640 x 480 images
  double bearing_noise_px = 1.0;    // noise of the reference bearing (px)
  double track_noise_px = 0.5;      // noise of each track (px)
  int num_target_points = 150;      // feature points on the target, seen when their face is (count)
  double sfm_relative_scale = 3.0;  // true scale: world units per object map unit
  double sfm_start_s = 0.5;         // the target's reconstruction exists from this time (s)
  double sfm_rotation_noise_rad = 0.002;       // per image (rad)
  double sfm_translation_noise_ratio = 0.002;  // per image, fraction of the distance
  double depth_bound_near = 1.0;               // near end of the depth bound (m)
  int num_static_points = 1500;                // static map points for the ground plane (count)
  double static_outlier_ratio = 0.2;           // share of them that are random outliers
  double ground_point_noise = 0.02;            // height noise of ground points (m)
  uint64_t seed = 1;
};

struct BotSimFrame {
  int64_t utime = 0;
  Rigid3d cam_from_world;     // truth (and what the static SLAM would give)
  Rigid3d world_from_target;  // truth: target box centre and heading
  Eigen::Vector3d reference_in_world = Eigen::Vector3d::Zero();  // truth: the tracked point
  Eigen::Vector3d target_velocity = Eigen::Vector3d::Zero();     // truth (m/s)
  bool visible = true;         // reference point in front of the camera and in the image
  BotObservation observation;  // what the tracker gets (when visible)
};

struct BotSimSequence {
  BotSimOptions options;
  std::vector<BotSimFrame> frames;
  std::vector<Eigen::Vector3d> static_points;
  GroundPlaneEstimate ground_plane;                               // estimated from static_points
  Eigen::Vector3d target_size = Eigen::Vector3d::Zero();          // length, width, height (m)
  Eigen::Vector3d reference_in_target = Eigen::Vector3d::Zero();  // (m)
};

Status SimulateBotSequence(const BotSimOptions& options, BotSimSequence* sequence);

// One tracker run over a sequence, scored against the truth.
struct BotRunFrame {
  double t_s = 0.0;             // since initialisation (s)
  double depth_true = 0.0;      // camera depth of the reference point (m)
  double depth_mean = 0.0;      // (m)
  double depth_sigma = 0.0;     // (m)
  double position_error = 0.0;  // |estimate - truth| of the reference point (m)
  double range = 0.0;           // distance camera - reference point (m)
  double ess = 0.0;
  bool reliable = false;
  std::optional<double> relative_scale;
  std::vector<PredictedVolume> volumes;
};

struct BotRunResult {
  std::vector<BotRunFrame> frames;
  // Share of the images whose volume at the horizon contained the true target centre at
  // that time (images whose horizon lies past the end are not counted); -1 if none.
  double HitRate(int64_t horizon_us) const;
  // The frame closest to t_s seconds after initialisation.
  const BotRunFrame& At(double t_s) const;
  std::vector<Eigen::Vector3d> truth_centers;  // target centre per image
  std::vector<int64_t> utimes;
};

Status RunBotSequence(const BotSimSequence& sequence, const BearingOnlyTrackerOptions& options,
                      int64_t object_id, BotRunResult* result);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_OBJECTS_BOT_SIMULATION_H_
