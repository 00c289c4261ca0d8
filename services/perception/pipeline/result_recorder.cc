#include "services/perception/pipeline/result_recorder.h"

#include <sys/stat.h>

#include <algorithm>
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
    for (TimedPose& p : camera_) p.pose.translation *= *r.world_rescaled_by;
    for (auto& [id, poses] : objects_) {
      for (TimedPose& p : poses) p.pose.translation *= *r.world_rescaled_by;
    }
  }
  // Poses recovered for earlier images (in time order, all before this image): inserted
  // in order, an image already in the trajectory is not repeated.
  for (const auto& [utime, world_from_cam] : r.backfilled_camera_poses) {
    auto at = std::lower_bound(camera_.begin(), camera_.end(), utime,
                               [](const TimedPose& p, int64_t t) { return p.utime < t; });
    if (at != camera_.end() && at->utime == utime) continue;
    camera_.insert(at, TimedPose{utime, world_from_cam});
    ++backfilled_;
  }
  const TrackingState s = r.camera_pose.tracking_state;
  if (s == TrackingState::kOk || s == TrackingState::kRelocalized) {
    ++tracked_;
    camera_.push_back(TimedPose{r.camera_pose.utime, r.camera_pose.world_from_cam});
    while (camera_.size() > max_poses_) {
      camera_.pop_front();
      ++camera_poses_dropped_;
    }
  }
  for (const ObjectOutput& o : r.objects) {
    if (o.state == ObjectState::kDetected) continue;
    objects_[o.id].push_back(TimedPose{r.utime, o.world_from_object});
    ++object_poses_;
  }
  for (const ObjectReconstructionOutput& o : r.object_reconstructions) {
    Reconstruction& rec = reconstructions_[{o.object_id, o.map_id}];
    rec.obj_from_cam.push_back(TimedPose{r.utime, o.cam_from_obj.Inverse()});
    if (o.points_included) rec.points = o.points;
    ++object_poses_;
  }
  // Over the budget: the oldest objects' trajectories (and reconstructions) go first, whole.
  while (object_poses_ > max_poses_ && (objects_.size() > 1 || reconstructions_.size() > 1)) {
    const bool drop_object =
        reconstructions_.empty() || (!objects_.empty() && objects_.begin()->first <= reconstructions_.begin()->first.first);
    const size_t n = drop_object ? objects_.begin()->second.size() : reconstructions_.begin()->second.obj_from_cam.size();
    object_poses_ -= n;
    object_poses_dropped_ += static_cast<int64_t>(n);
    if (drop_object) objects_.erase(objects_.begin());
    else reconstructions_.erase(reconstructions_.begin());
  }
  if (r.map) map_ = r.map;
  if (r.occupancy) occupancy_ = r.occupancy;
}

void ResultRecorder::OnAdjustedCameraTrajectory(const std::vector<std::pair<int64_t, Rigid3d>>& world_from_cam) {
  std::lock_guard<std::mutex> lock(mutex_);
  adjusted_camera_.clear();
  for (const auto& [utime, pose] : world_from_cam) adjusted_camera_[utime] = pose;
}

int64_t ResultRecorder::frames() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return frames_;
}

int64_t ResultRecorder::RetainedBytes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  // A red-black tree node: three pointers and the colour, then the value.
  constexpr size_t kTreeNode = 4 * sizeof(void*);
  size_t bytes = camera_.size() * sizeof(TimedPose);
  for (const auto& [id, poses] : objects_) {
    bytes += kTreeNode + sizeof(id) + sizeof(poses) + poses.capacity() * sizeof(TimedPose);
  }
  for (const auto& [key, rec] : reconstructions_) {
    bytes += kTreeNode + sizeof(key) + sizeof(rec) + rec.obj_from_cam.capacity() * sizeof(TimedPose) +
             rec.points.capacity() * sizeof(Eigen::Vector3f);
  }
  return static_cast<int64_t>(bytes);
}

Status ResultRecorder::Write(const std::string& dir, const std::string& extra_summary) const {
  std::lock_guard<std::mutex> lock(mutex_);
  ::mkdir(dir.c_str(), 0755);
  ::mkdir((dir + "/objects").c_str(), 0755);
  // A process killed during an earlier save leaves its temporary files behind.
  RemoveStaleTempFiles(dir);
  RemoveStaleTempFiles(dir + "/objects");
  int64_t adjusted = 0;
  {
    // The images' poses as the map finally has them where it still does (after the
    // last image), else as published.
    std::ostringstream out, live;
    out << "# world_from_cam, TUM format: t tx ty tz qx qy qz qw\n";
    live << "# world_from_cam as published live, TUM format: t tx ty tz qx qy qz qw\n";
    for (const TimedPose& p : camera_) {
      auto a = adjusted_camera_.find(p.utime);
      adjusted += a != adjusted_camera_.end();
      out << TumLine(p.utime, a != adjusted_camera_.end() ? a->second : p.pose) << "\n";
      live << TumLine(p.utime, p.pose) << "\n";
    }
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(dir + "/camera_trajectory.tum", out.str()));
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(dir + "/camera_trajectory_live.tum", live.str()));
  }
  for (const auto& [id, poses] : objects_) {
    std::ostringstream out;
    out << "# world_from_object " << id << ", TUM format\n";
    for (const TimedPose& p : poses) out << TumLine(p.utime, p.pose) << "\n";
    MBSLAM_RETURN_IF_ERROR(
        WriteStringAtomically(dir + "/objects/" + std::to_string(id) + ".tum", out.str()));
  }
  if (!reconstructions_.empty()) {
    ::mkdir((dir + "/reconstructions").c_str(), 0755);
    RemoveStaleTempFiles(dir + "/reconstructions");
  }
  for (const auto& [key, rec] : reconstructions_) {
    const std::string base = dir + "/reconstructions/" + std::to_string(key.first) + "_" + std::to_string(key.second);
    std::ostringstream traj;
    traj << "# object " << key.first << ", map " << key.second
         << ": obj_from_cam (the camera in the object's own map, its units), TUM format\n";
    for (const TimedPose& p : rec.obj_from_cam) traj << TumLine(p.utime, p.pose) << "\n";
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(base + ".tum", traj.str()));
    std::ostringstream pts;
    pts << "# object " << key.first << ", map " << key.second << ": points in the object's own map: x y z\n";
    for (const Eigen::Vector3f& p : rec.points) pts << p.x() << " " << p.y() << " " << p.z() << "\n";
    MBSLAM_RETURN_IF_ERROR(WriteStringAtomically(base + ".xyz", pts.str()));
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
       << ",\n  \"frames_backfilled\": " << backfilled_
       << ",\n  \"frames_adjusted\": " << adjusted
       << ",\n  \"posed_fraction\": " << (frames_ ? double(tracked_ + backfilled_) / frames_ : 0.0)
       << ",\n  \"first_utime\": " << first_utime_ << ",\n  \"last_utime\": " << last_utime_
       << ",\n  \"objects_with_trajectory\": " << objects_.size()
       << ",\n  \"object_reconstructions\": " << reconstructions_.size()
       << ",\n  \"map_points\": " << (map_ ? map_->points.size() : 0)
       << ",\n  \"occupied_voxels\": " << (occupancy_ ? occupancy_->num_occupied : 0)
       << ",\n  \"camera_poses_dropped\": " << camera_poses_dropped_
       << ",\n  \"object_poses_dropped\": " << object_poses_dropped_;
  if (!extra_summary.empty()) json << ",\n  " << extra_summary;
  json << "\n}\n";
  return WriteStringAtomically(dir + "/summary.json", json.str());
}

}  // namespace mbslam
