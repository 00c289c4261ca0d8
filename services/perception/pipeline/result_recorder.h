#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_RESULT_RECORDER_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_RESULT_RECORDER_H_

// Keeps what the output files need (camera and object trajectories, the latest map
// and occupancy, run statistics) and writes them atomically on request or exit:
//   camera_trajectory.tum (the poses as the map finally has them, where it does),
//   camera_trajectory_live.tum (as published), objects/<id>.tum, map.ply, occupancy.bt,
//   summary.json

#include <deque>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "common/util/status.h"
#include "services/perception/pipeline/outputs.h"

namespace mbslam {

class ResultRecorder : public OutputSink {
 public:
  // Trajectories keep at most `max_poses` poses each for the camera and, in total, for
  // the objects (64 bytes a pose); beyond that the oldest go (counted in summary.json),
  // so a service running for days does not grow without bound.
  static constexpr size_t kDefaultMaxPoses = size_t{1} << 20;  // ~9.7 h at 30 Hz, 64 MB
  explicit ResultRecorder(size_t max_poses = kDefaultMaxPoses) : max_poses_(max_poses) {}

  void OnFrameResult(const FrameResult& result) override;
  // The final adjusted poses replace the live ones of the same images in
  // camera_trajectory.tum; camera_trajectory_live.tum keeps the poses as published.
  void OnAdjustedCameraTrajectory(const std::vector<std::pair<int64_t, Rigid3d>>& world_from_cam) override;

  // Writes every output file into `dir` (created if missing). `extra_summary` is a
  // JSON object body (without braces) merged into summary.json; may be empty.
  Status Write(const std::string& dir, const std::string& extra_summary) const;

  int64_t frames() const;

  // What the recorder's trajectories and object reconstructions hold, from their
  // containers' sizes and capacities (bytes; the allocator's per-block overhead aside).
  // It grows with the run up to the pose budget (the latest map and occupancy copies are
  // bounded with the map and not counted): what a soak test must not take for a leak.
  int64_t RetainedBytes() const;

 private:
  struct TimedPose {
    int64_t utime = 0;  // µs
    Rigid3d pose;       // world_from_cam / world_from_object
  };

  const size_t max_poses_;
  mutable std::mutex mutex_;
  std::deque<TimedPose> camera_;  // tracked frames only, oldest first
  std::map<int64_t, Rigid3d> adjusted_camera_;  // utime -> world_from_cam, after the last image
  std::map<int, std::vector<TimedPose>> objects_;  // ids grow with time: begin() is the oldest
  size_t object_poses_ = 0;
  int64_t camera_poses_dropped_ = 0;
  int64_t object_poses_dropped_ = 0;
  // Objects' own reconstructions, by (object id, map id): the camera in the object's map
  // (obj_from_cam) per image and the latest points; counted with the object poses.
  struct Reconstruction {
    std::vector<TimedPose> obj_from_cam;
    std::vector<Eigen::Vector3f> points;
  };
  std::map<std::pair<int, int64_t>, Reconstruction> reconstructions_;
  std::optional<MapOutput> map_;
  std::optional<OccupancyOutput> occupancy_;
  int64_t frames_ = 0;
  int64_t tracked_ = 0;     // images with a live pose (OK or relocalised)
  int64_t backfilled_ = 0;  // earlier images whose pose was recovered when a map was confirmed or tracking came back
  int64_t first_utime_ = 0;
  int64_t last_utime_ = 0;
};

// Fans results out to several sinks in order.
class TeeSink : public OutputSink {
 public:
  explicit TeeSink(std::vector<OutputSink*> sinks) : sinks_(std::move(sinks)) {}
  void OnFrameResult(const FrameResult& result) override {
    for (OutputSink* s : sinks_) s->OnFrameResult(result);
  }
  void OnAdjustedCameraTrajectory(const std::vector<std::pair<int64_t, Rigid3d>>& world_from_cam) override {
    for (OutputSink* s : sinks_) s->OnAdjustedCameraTrajectory(world_from_cam);
  }

 private:
  std::vector<OutputSink*> sinks_;
};

// One TUM line: "t tx ty tz qx qy qz qw" with t in seconds (µs precision).
std::string TumLine(int64_t utime, const Rigid3d& pose);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_RESULT_RECORDER_H_
