#ifndef MBSLAM_TOOLS_EVAL_TRAJECTORY_H_
#define MBSLAM_TOOLS_EVAL_TRAJECTORY_H_

// Time-stamped poses (world_from_x, int64 µs) and their file formats, and association
// of two trajectories by timestamp.

#include <cstdint>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {
namespace eval {

struct TimedPose {
  int64_t utime = 0;  // µs
  Rigid3d pose;       // world_from_x (e.g. world_from_cam)
};
using Trajectory = std::vector<TimedPose>;

// "s.uuuuuu" with exactly six decimals (exact for any int64 µs).
std::string UtimeToSecondsString(int64_t utime);
// Seconds as decimal text -> µs, exactly for up to six decimals (rounded beyond; other
// forms such as exponents go through strtod). False on malformed text.
bool ParseSecondsToUtime(const std::string& token, int64_t* utime);

// TUM format: one pose per line "t tx ty tz qx qy qz qw" (t in s, any whitespace or
// commas, '#' comments). Poses are sorted by time; duplicate times are an error.
Status ParseTumTrajectory(const std::string& text, Trajectory* trajectory);
Status ReadTumTrajectory(const std::string& path, Trajectory* trajectory);
std::string FormatTumLine(int64_t utime, const Rigid3d& pose);
Status WriteTumTrajectory(const std::string& path, const Trajectory& trajectory,
                          const std::string& header_comment = "");

// TartanAir pose_left.txt: one line "tx ty tz qx qy qz qw" per frame, camera in world in
// NED axes (x forward, y right, z down). Returned as world_from_cam with the camera axes
// of this project (x right, y down, z forward); frame i gets utime = i * frame_period_us.
Status ReadTartanAirPoses(const std::string& path, int64_t frame_period_us, Trajectory* trajectory);

// One-to-one association of poses by time: for each estimate the ground-truth pose
// nearest in time, if within max_dt_us; conflicts resolved by smallest time difference.
struct AssociatedPair {
  size_t est = 0;     // index into the estimate
  size_t gt = 0;      // index into the ground truth
  int64_t dt_us = 0;  // est time - gt time (µs)
};
std::vector<AssociatedPair> AssociateByTime(const Trajectory& est, const Trajectory& gt,
                                            int64_t max_dt_us);

// Sorts by time.
void SortByTime(Trajectory* trajectory);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_TRAJECTORY_H_
