#include "services/perception/pipeline/result_recorder.h"

#include <sys/stat.h>

#include <cstdio>
#include <sstream>

#include "common/util/atomic_file.h"

namespace mbslam {

std::string TumLine(int64_t utime, const Rigid3d& pose) {
  char buf[256];
  const Eigen::Quaterniond& q = pose.rotation;
  std::snprintf(buf, sizeof(buf), "%lld.%06lld %.9f %.9f %.9f %.9f %.9f %.9f %.9f",
                static_cast<long long>(utime / 1000000), static_cast<long long>(utime % 1000000),
                pose.translation.x(), pose.translation.y(), pose.translation.z(), q.x(), q.y(),
                q.z(), q.w());
  return buf;
}

void ResultRecorder::OnFrameResult(const FrameResult& r) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (frames_ == 0) first_utime_ = r.utime;
  last_utime_ = r.utime;
  ++frames_;
  if (r.world_rescaled_by) {
    // Keep the whole trajectory in one unit.
    for (CameraPoseOutput& p : camera_) p.world_from_cam.translation *= *r.world_rescaled_by;
    for (auto& [id, poses] : objects_) {
      for (auto& [utime, pose] : poses) pose.translation *= *r.world_rescaled_by;
    }
  }
  const TrackingState s = r.camera_pose.tracking_state;
  if (s == TrackingState::kOk || s == TrackingState::kRelocalized) {
    ++tracked_;
    camera_.push_back(r.camera_pose);
  }
  for (const ObjectOutput& o : r.objects) {
    if (o.state != ObjectState::kDetected) objects_[o.id].emplace_back(r.utime, o.world_from_object);
  }
  if (r.map) map_ = r.map;
  if (r.occupancy) occupancy_ = r.occupancy;
}

int64_t ResultRecorder::frames() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

Status ResultRecorder::Write(const std::string& dir, const std::string& extra_summary) const {
  std::lock_guard<std::mutex> lock(mutex_);
  ::mkdir(dir.c_str(), 0755);
  ::mkdir((dir + "/objects").c_str(), 0755);
  {
    std::ostringstream out;
    out << "# world_from_cam, TUM format: t tx ty tz qx qy qz qw\n";
    for (const CameraPoseOutput& p : camera_) out << TumLine(p.utime, p.world_from_cam) << "\n";
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(dir + "/camera_trajectory.tum", out.str()));
  }
  for (const auto& [id, poses] : objects_) {
    std::ostringstream out;
    out << "# world_from_object " << id << ", TUM format\n";
    for (const auto& [utime, pose] : poses) out << TumLine(utime, pose) << "\n";
    MBSLAM_RETURN_IF_ERROR(
        WriteStringAtomically(dir + "/objects/" + std::to_string(id) + ".tum", out.str()));
  }
  if (map_) {
    std::ostringstream out;
    out << "ply\nformat ascii 1.0\nelement vertex " << map_->points.size()
        << "\nproperty float x\nproperty float y\nproperty float z\n"
           "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    for (size_t i = 0; i < map_->points.size(); ++i) {
      const auto& p = map_->points[i];
      const std::array<uint8_t, 3> c =
          i < map_->colors.size() ? map_->colors[i] : std::array<uint8_t, 3>{200, 200, 200};
      out << p.x() << " " << p.y() << " " << p.z() << " " << int(c[0]) << " " << int(c[1]) << " "
          << int(c[2]) << "\n";
    }
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(dir + "/map.ply", out.str()));
  }
  if (occupancy_) {
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(dir + "/occupancy.bt", occupancy_->octree_binary));
  }
  std::ostringstream json;
  json << "{\n  \"frames\": " << frames_ << ",\n  \"frames_tracked\": " << tracked_
       << ",\n  \"tracked_fraction\": " << (frames_ ? double(tracked_) / frames_ : 0.0)
       << ",\n  \"first_utime\": " << first_utime_ << ",\n  \"last_utime\": " << last_utime_
       << ",\n  \"objects_with_trajectory\": " << objects_.size()
       << ",\n  \"map_points\": " << (map_ ? map_->points.size() : 0)
       << ",\n  \"occupied_voxels\": " << (occupancy_ ? occupancy_->num_occupied : 0);
  if (!extra_summary.empty()) json << ",\n  " << extra_summary;
  json << "\n}\n";
  return WriteStringAtomically(dir + "/summary.json", json.str());
}

}  // namespace mbslam
