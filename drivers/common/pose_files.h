#ifndef MBSLAM_DRIVERS_COMMON_POSE_FILES_H_
#define MBSLAM_DRIVERS_COMMON_POSE_FILES_H_

// Readers and writers of the trajectory files datasets come with.
//
//   TUM:       "t tx ty tz qx qy qz qw" per line, t in seconds, '#' comments;
//              the pose is target_from_source (e.g. world_from_cam).
//   KITTI:     12 numbers per line, the row-major 3x4 matrix [R | t] of one frame.
//   TartanAir: "tx ty tz qx qy qz qw" per line (one per frame), the pose of a body
//              with NED axes (x forward, y right, z down); converted here to the
//              camera's optical axes (x right, y down, z forward).

#include <cstdint>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "services/perception/geometry/rigid3.h"

namespace mbslam {

struct TimedPose {
  int64_t utime = 0;  // µs
  Rigid3d pose;
};

// Decimal seconds ("1305031102.175304", "12", "1.5e-3") to µs. Plain decimals are
// converted exactly (rounded half away from zero at the 7th decimal); exponent
// notation goes through double.
Status ParseSecondsToUtime(const std::string& text, int64_t* utime);
// The same for a number in `unit` ("s", "ms", "us", "ns").
Status ParseTimeToUtime(const std::string& text, const std::string& unit, int64_t* utime);
bool IsValidTimeUnit(const std::string& unit);

// Splits a line at spaces, tabs and commas (empty fields dropped).
std::vector<std::string> SplitFields(const std::string& line);

// Quaternion from x y z w components; fails unless |q| is within 2 % of 1 (then
// normalised), so truncated dataset files still load but garbage does not.
Status QuaternionFromXyzw(double x, double y, double z, double w, Eigen::Quaterniond* q);

Status ReadTumTrajectory(const std::string& path, std::vector<TimedPose>* poses);
Status WriteTumTrajectory(const std::string& path, const std::vector<TimedPose>& poses);
Status ReadKittiPoses(const std::string& path, std::vector<Rigid3d>* poses);
Status ReadTartanAirPoses(const std::string& path, std::vector<Rigid3d>* world_from_cam);

// body_from_optical for a NED body frame (x forward, y right, z down).
Rigid3d NedBodyFromOptical();

}  // namespace mbslam

#endif  // MBSLAM_DRIVERS_COMMON_POSE_FILES_H_
