// handeye_calib: estimates the robot-to-camera extrinsic base_from_cam from paired
// camera / odometry motions (AX = XB, see handeye.h for what is observable) and
// prints it with residuals.
//
//   handeye_calib --camera CAM.tum --odometry ODOM.tum|csv [options]
//   handeye_calib --log RUN.lcmlog [--camera-channel GROUND_TRUTH|PERCEPTION_CAMERA_POSE]

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/lcm/lcm_log.h"
#include "common/lcm/wire_check.h"
#include "common/util/atomic_file.h"
#include "drivers/common/command_line.h"
#include "drivers/common/exit_codes.h"
#include "drivers/common/pose_files.h"
#include "drivers/odometry_bridge/handeye.h"
#include "drivers/odometry_bridge/odometry_bridge_options.h"
#include "drivers/odometry_bridge/odometry_files.h"
#include "mbslam/camera_pose_t.hpp"
#include "mbslam/ground_truth_t.hpp"
#include "mbslam/odometry_t.hpp"

namespace mbslam {
namespace {

constexpr char kUsage[] = R"(usage: handeye_calib (--camera CAM --odometry ODOM | --log LOG) [options]

Estimates base_from_cam (the camera pose in the robot base frame) from paired motions.

  --camera FILE           camera trajectory world_from_cam, TUM format (any scale)
  --odometry FILE         odometry odom_from_base: TUM format, or CSV (.csv, see odometry_bridge)
  --log FILE              an LCM log with camera poses and ODOMETRY instead
  --camera-channel C      camera poses in the log: GROUND_TRUTH (ground_truth_t) or a
                          camera_pose_t channel (default PERCEPTION_CAMERA_POSE)
  --odometry-channel C    odometry_t channel in the log (default ODOMETRY)
  --mode M                auto | general | planar (default auto)
  --metric-camera         camera translations are metric (fix the scale to 1)
  --prior-offset M        planar: camera offset along the turn axis (unobservable), m
  --min-rotation-deg D    a motion pair ends after this much turning (default 5)
  --min-translation M     ... or this much driving (default 0.2 m)
  --output FILE           write the result as YAML (odometry_bridge base_from_cam.file)
  --verbose               print the residual of every motion pair

Exit codes: 0 done, 2 bad arguments / files, 3 input not found, 6 the motions cannot
determine the extrinsic (e.g. the robot never turned).
)";

int Fail(int code, const std::string& message) {
  std::fprintf(stderr, "handeye_calib: %s\n", message.c_str());
  return code;
}

Status LoadFromLog(const std::string& path, const std::string& camera_channel,
                   const std::string& odometry_channel, std::vector<TimedPose>* camera,
                   std::vector<TimedPose>* odometry) {
  std::vector<LcmLogEvent> events;
  MBSLAM_RETURN_IF_ERROR(ReadLcmLog(path, &events));
  for (const LcmLogEvent& e : events) {
    if (e.channel == odometry_channel) {
      mbslam::odometry_t msg{};
      if (!DecodeLcmMessage(e.data.data(), e.data.size(), &msg).ok()) continue;
      TimedPose p;
      p.utime = msg.utime;
      p.pose = Rigid3d(Eigen::Quaterniond(msg.orientation[0], msg.orientation[1], msg.orientation[2], msg.orientation[3]),
                       Eigen::Vector3d(msg.position[0], msg.position[1], msg.position[2]));
      if (odometry->empty() || p.utime > odometry->back().utime) odometry->push_back(p);
    } else if (e.channel == camera_channel) {
      TimedPose p;
      if (camera_channel == "GROUND_TRUTH") {
        mbslam::ground_truth_t msg{};
        if (!DecodeLcmMessage(e.data.data(), e.data.size(), &msg).ok() || !msg.has_camera) continue;
        p.utime = msg.utime;
        p.pose = Rigid3d(Eigen::Quaterniond(msg.cam_orientation[0], msg.cam_orientation[1],
                                            msg.cam_orientation[2], msg.cam_orientation[3]),
                         Eigen::Vector3d(msg.cam_position[0], msg.cam_position[1], msg.cam_position[2]));
      } else {
        mbslam::camera_pose_t msg{};
        if (!DecodeLcmMessage(e.data.data(), e.data.size(), &msg).ok()) continue;
        if (msg.tracking_state != mbslam::camera_pose_t::TRACKING_OK &&
            msg.tracking_state != mbslam::camera_pose_t::TRACKING_RELOCALIZED) {
          continue;
        }
        p.utime = msg.utime;
        p.pose = Rigid3d(Eigen::Quaterniond(msg.orientation[0], msg.orientation[1], msg.orientation[2], msg.orientation[3]),
                         Eigen::Vector3d(msg.position[0], msg.position[1], msg.position[2]));
      }
      if (camera->empty() || p.utime > camera->back().utime) camera->push_back(p);
    }
  }
  if (camera->empty()) return Status::Error(path + ": no camera poses on " + camera_channel);
  if (odometry->empty()) return Status::Error(path + ": no odometry on " + odometry_channel);
  return Status::Ok();
}

int Main(int argc, char** argv) {
  CommandLine cl;
  Status st = CommandLine::Parse(argc, argv, {"help", "metric-camera", "verbose"},
                                 {"camera", "odometry", "log", "camera-channel", "odometry-channel", "mode",
                                  "prior-offset", "min-rotation-deg", "min-translation", "output"},
                                 &cl);
  if (!st.ok()) return Fail(kExitUsage, st.message());
  if (cl.Has("help")) {
    std::fputs(kUsage, stdout);
    return kExitOk;
  }
  std::vector<TimedPose> camera, odometry;
  if (cl.Has("log")) {
    std::FILE* f = std::fopen(cl.Get("log").c_str(), "rb");
    if (f == nullptr) return Fail(kExitInputNotFound, "cannot open " + cl.Get("log"));
    std::fclose(f);
    st = LoadFromLog(cl.Get("log"), cl.Get("camera-channel", "PERCEPTION_CAMERA_POSE"),
                     cl.Get("odometry-channel", "ODOMETRY"), &camera, &odometry);
    if (!st.ok()) return Fail(kExitUsage, st.message());
  } else {
    if (!cl.Has("camera") || !cl.Has("odometry")) {
      return Fail(kExitUsage, "give --camera and --odometry, or --log (try --help)");
    }
    for (const std::string& path : {cl.Get("camera"), cl.Get("odometry")}) {
      std::FILE* f = std::fopen(path.c_str(), "r");
      if (f == nullptr) return Fail(kExitInputNotFound, "cannot open " + path);
      std::fclose(f);
    }
    st = ReadTumTrajectory(cl.Get("camera"), &camera);
    if (!st.ok()) return Fail(kExitUsage, st.message());
    const std::string odo = cl.Get("odometry");
    if (odo.size() > 4 && odo.compare(odo.size() - 4, 4, ".csv") == 0) {
      std::vector<OdometrySample> samples;
      st = ReadOdometryCsv(odo, &samples);
      for (const OdometrySample& s : samples) odometry.push_back(TimedPose{s.utime, s.odom_from_base});
    } else {
      st = ReadTumTrajectory(odo, &odometry);
    }
    if (!st.ok()) return Fail(kExitUsage, st.message());
  }
  HandEyeOptions options;
  PairingOptions pairing;
  options.mode = cl.Get("mode", "auto");
  options.metric_camera = cl.Has("metric-camera");
  for (const Status& s :
       {ParseDouble(cl.Get("prior-offset", "0"), "--prior-offset", &options.prior_offset_along_axis_m),
        ParseDouble(cl.Get("min-rotation-deg", "5"), "--min-rotation-deg", &pairing.min_rotation_deg),
        ParseDouble(cl.Get("min-translation", "0.2"), "--min-translation", &pairing.min_translation_m)}) {
    if (!s.ok()) return Fail(kExitUsage, s.message());
  }
  if (!options.Check()) return Fail(kExitUsage, "bad --mode (auto | general | planar)");
  std::vector<MotionPair> pairs;
  int outside = 0;
  st = BuildMotionPairs(camera, odometry, pairing, &pairs, &outside);
  if (!st.ok()) return Fail(kExitUsage, st.message());
  std::printf("camera poses: %zu, odometry samples: %zu, camera poses outside the odometry: %d, motion pairs: %zu\n",
              camera.size(), odometry.size(), outside, pairs.size());
  HandEyeResult result;
  st = SolveHandEye(pairs, options, &result);
  if (!st.ok()) return Fail(kExitDegenerateData, st.message());

  const Rigid3d& x = result.base_from_cam;
  const Eigen::Matrix3d r = x.RotationMatrix();
  constexpr double kRadToDeg = 180.0 / M_PI;
  std::printf("base_from_cam (camera pose in the robot base frame):\n");
  std::printf("  translation [m]:      % .6f % .6f % .6f\n", x.translation.x(), x.translation.y(), x.translation.z());
  std::printf("  quaternion [w x y z]: % .6f % .6f % .6f % .6f\n", x.rotation.w(), x.rotation.x(), x.rotation.y(), x.rotation.z());
  for (int i = 0; i < 3; ++i) {
    std::printf("  %s [% .6f % .6f % .6f]\n", i == 0 ? "rotation:" : "         ", r(i, 0), r(i, 1), r(i, 2));
  }
  std::printf("  scale: %.6f m per camera unit%s\n", result.scale, options.metric_camera ? " (fixed)" : "");
  std::printf("observability: %s\n", result.observability.c_str());
  double rot_max = 0, trans_max = 0;
  for (double v : result.rotation_residuals_rad) rot_max = std::max(rot_max, v);
  for (double v : result.translation_residuals_m) trans_max = std::max(trans_max, v);
  std::printf("residuals over %d motion pairs (%d turning): rotation RMS %.4f deg (max %.4f), "
              "translation RMS %.4f m (max %.4f)\n",
              result.pairs, result.rotating_pairs, result.rotation_rms_rad * kRadToDeg, rot_max * kRadToDeg,
              result.translation_rms_m, trans_max);
  if (cl.Has("verbose")) {
    std::printf("  pair  t0 [s]            t1 [s]            rot [deg]  trans [m]\n");
    for (size_t i = 0; i < pairs.size(); ++i) {
      std::printf("  %4zu  %.6f  %.6f  %9.4f  %9.4f\n", i, pairs[i].utime0 * 1e-6, pairs[i].utime1 * 1e-6,
                  result.rotation_residuals_rad[i] * kRadToDeg, result.translation_residuals_m[i]);
    }
  }
  if (cl.Has("output")) {
    char comment[512];
    std::snprintf(comment, sizeof(comment),
                  "handeye_calib: %d motion pairs, rotation RMS %.4f deg, translation RMS %.4f m, scale %.6f\n%s",
                  result.pairs, result.rotation_rms_rad * kRadToDeg, result.translation_rms_m, result.scale,
                  result.observability.c_str());
    st = WriteStringAtomically(cl.Get("output"), ExtrinsicToYaml(x, comment));
    if (!st.ok()) return Fail(kExitOutputError, st.message());
    std::printf("written to %s\n", cl.Get("output").c_str());
  }
  return kExitOk;
}

}  // namespace
}  // namespace mbslam

int main(int argc, char** argv) {
  try {
    return mbslam::Main(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "handeye_calib: unexpected error: %s\n", e.what());
    return mbslam::kExitRuntimeError;
  }
}
