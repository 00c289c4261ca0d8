#ifndef MBSLAM_SERVICES_PERCEPTION_PIPELINE_RESULT_RECORDER_H_
#define MBSLAM_SERVICES_PERCEPTION_PIPELINE_RESULT_RECORDER_H_

// Keeps what the output files need (camera and object trajectories, the latest map
// and occupancy, run statistics) and writes them atomically on request or exit:
//   camera_trajectory.tum, objects/<id>.tum, map.ply, occupancy.bt, summary.json

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
  void OnFrameResult(const FrameResult& result) override;

  // Writes every output file into `dir` (created if missing). `extra_summary` is a
  // JSON object body (without braces) merged into summary.json; may be empty.
  Status Write(const std::string& dir, const std::string& extra_summary) const;

  int64_t frames() const;

 private:
  mutable std::mutex mutex_;
  std::vector<CameraPoseOutput> camera_;  // tracked frames only
  std::map<int, std::vector<std::pair<int64_t, Rigid3d>>> objects_;
  std::optional<MapOutput> map_;
  std::optional<OccupancyOutput> occupancy_;
  int64_t frames_ = 0;
  int64_t tracked_ = 0;
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

 private:
  std::vector<OutputSink*> sinks_;
};

// One TUM line: "t tx ty tz qx qy qz qw" with t in seconds (µs precision).
std::string TumLine(int64_t utime, const Rigid3d& pose);

}  // namespace mbslam

#endif  // MBSLAM_SERVICES_PERCEPTION_PIPELINE_RESULT_RECORDER_H_
