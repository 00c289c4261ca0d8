#ifndef MBSLAM_TOOLS_EVAL_LCM_READERS_H_
#define MBSLAM_TOOLS_EVAL_LCM_READERS_H_

// Reading evaluation inputs from the project's LCM logs: estimated camera poses
// (camera_pose_t), ground truth (ground_truth_t), estimated objects (objects_t).

#include <map>
#include <string>

#include "common/util/status.h"
#include "tools/eval/object_metrics.h"
#include "tools/eval/trajectory.h"

namespace mbslam {
namespace eval {

struct CameraPoseLog {
  Trajectory tracked;    // poses with tracking_state TRACKING_OK or TRACKING_RELOCALIZED
  int num_messages = 0;  // camera_pose_t messages (count)
  int num_metric = 0;    // of them with scale_state SCALE_METRIC (count)
  int num_undecodable = 0;
};
Status ReadCameraPoseLog(const std::string& path, const std::string& channel, CameraPoseLog* log);

struct GroundTruthLog {
  std::string source;               // e.g. "sim:crossing"
  Trajectory camera;                // world_from_cam per image (messages with has_camera)
  std::map<int, BodyTruth> bodies;  // moving bodies by id
  int num_messages = 0;
};
Status ReadGroundTruthLog(const std::string& path, const std::string& channel, GroundTruthLog* log);

// Objects by id, one sample per objects_t message in which they appear with an estimate
// (an object without particles or volumes is listed without a sample: its position is
// not given).
Status ReadObjectsLog(const std::string& path, const std::string& channel,
                      std::map<int, ObjectEstimate>* objects, int* num_messages = nullptr);

// Number of events on a channel (e.g. images).
Status CountLogEvents(const std::string& path, const std::string& channel, int* count);

}  // namespace eval
}  // namespace mbslam

#endif  // MBSLAM_TOOLS_EVAL_LCM_READERS_H_
