#include "viewer/scene.h"

#include <algorithm>
#include <utility>

#include "common/util/logging.h"
#include "viewer/occupancy_decode.h"

namespace mbslam {
namespace viewer {

bool HasPose(TrackingState state) {
  return state == TrackingState::kOk || state == TrackingState::kLost ||
         state == TrackingState::kRelocalized;
}

SceneState::SceneState(const SceneOptions& options) : options_(options) {}

void SceneState::Clear() {
  const SceneOptions options = options_;
  const int64_t resets = resets_;
  const int64_t decode_errors = occupancy_decode_errors_;
  *this = SceneState(options);
  resets_ = resets;
  occupancy_decode_errors_ = decode_errors;
}

void SceneState::Touch(int64_t utime) { latest_utime_ = std::max(latest_utime_, utime); }

// Positions before and after the scale became metric are in different units: the old
// trajectories would be drawn at the wrong size, so they start again.
void SceneState::ResetTrajectoriesOnUnitChange(bool metric) {
  if (have_unit_ && metric != metric_) {
    MBSLAM_LOG(INFO) << "viewer: scale changed to " << (metric ? "metric" : "up-to-scale")
                     << ", trajectories restart";
    trajectory_.clear();
    object_trajectories_.clear();
    object_last_seen_.clear();
  }
  have_unit_ = true;
  metric_ = metric;
}

void SceneState::AddCameraPose(const CameraPoseSample& pose) {
  if (current_camera_ && pose.utime < current_camera_->utime) {
    MBSLAM_LOG(WARNING) << "viewer: camera pose time went backwards (" << current_camera_->utime
                        << " -> " << pose.utime << " µs), the scene starts again";
    ++resets_;
    Clear();
  }
  Touch(pose.utime);
  ResetTrajectoriesOnUnitChange(pose.metric);
  current_camera_ = pose;
  if (pose.tracking_state == TrackingState::kOk ||
      pose.tracking_state == TrackingState::kRelocalized) {
    trajectory_.push_back(pose);
    if (static_cast<int>(trajectory_.size()) > options_.max_trajectory_points) {
      // Thin the older half instead of cutting the start: the whole path stays visible.
      std::vector<CameraPoseSample> thinned;
      thinned.reserve(trajectory_.size());
      const size_t half = trajectory_.size() / 2;
      for (size_t i = 0; i < trajectory_.size(); ++i) {
        if (i >= half || i % 2 == 0) thinned.push_back(trajectory_[i]);
      }
      trajectory_ = std::move(thinned);
    }
  }
}

void SceneState::SetMap(MapData map) {
  Touch(map.utime);
  map_ = std::move(map);
}

void SceneState::SetObjects(ObjectsData objects) {
  Touch(objects.utime);
  ResetTrajectoriesOnUnitChange(objects.metric);
  for (const ObjectData& o : objects.objects) {
    if (o.state == ObjectState::kDetected) continue;  // no reliable position yet
    auto& trajectory = object_trajectories_[o.id];
    trajectory.push_back(o.position);
    if (static_cast<int>(trajectory.size()) > options_.max_object_trajectory_points) {
      trajectory.erase(trajectory.begin(),
                       trajectory.begin() + static_cast<long>(trajectory.size() / 4));
    }
    object_last_seen_[o.id] = objects.utime;
  }
  while (static_cast<int>(object_trajectories_.size()) > options_.max_object_trajectories) {
    auto oldest =
        std::min_element(object_last_seen_.begin(), object_last_seen_.end(),
                         [](const auto& a, const auto& b) { return a.second < b.second; });
    object_trajectories_.erase(oldest->first);
    object_last_seen_.erase(oldest);
  }
  objects_.push_back(std::move(objects));
  while (static_cast<int>(objects_.size()) > options_.tracks_buffer) objects_.pop_front();
}

void SceneState::SetOccupancy(EncodedOccupancy occupancy) {
  Touch(occupancy.utime);
  occupancy_encoded_ = std::move(occupancy);
  occupancy_dirty_ = true;
}

const OccupancyData& SceneState::occupancy() const {
  if (occupancy_dirty_) {
    occupancy_dirty_ = false;
    OccupancyData decoded;
    const Status s = DecodeOccupancy(occupancy_encoded_.data.data(), occupancy_encoded_.data.size(),
                                     options_.max_voxels, &decoded);
    if (s.ok()) {
      decoded.utime = occupancy_encoded_.utime;
      occupancy_ = std::move(decoded);
    } else {
      ++occupancy_decode_errors_;
      MBSLAM_LOG(WARNING) << "viewer: occupancy at " << occupancy_encoded_.utime
                          << " µs does not decode: " << s.message();
      occupancy_ = OccupancyData();
    }
  }
  return occupancy_;
}

void SceneState::AddTracks(TracksData tracks) {
  Touch(tracks.utime);
  if (tracks.width > 0 && tracks.height > 0) {
    image_width_ = tracks.width;
    image_height_ = tracks.height;
  }
  tracks_.push_back(std::move(tracks));
  while (static_cast<int>(tracks_.size()) > options_.tracks_buffer) tracks_.pop_front();
}

void SceneState::AddImage(EncodedImage image) {
  Touch(image.utime);
  if (image_width_ == 0) {
    image_width_ = image.width;
    image_height_ = image.height;
  }
  images_.push_back(std::move(image));
  while (static_cast<int>(images_.size()) > options_.image_buffer) images_.pop_front();
}

ImageFrame SceneState::LatestImageFrame() const {
  ImageFrame frame;
  auto image_at = [this](int64_t utime) -> const EncodedImage* {
    for (auto it = images_.rbegin(); it != images_.rend(); ++it) {
      if (it->utime == utime) return &*it;
    }
    return nullptr;
  };
  auto objects_at = [this](int64_t utime) -> const ObjectsData* {
    for (auto it = objects_.rbegin(); it != objects_.rend(); ++it) {
      if (it->utime == utime) return &*it;
    }
    return nullptr;
  };
  // Newest tracks whose image is here.
  for (auto it = tracks_.rbegin(); it != tracks_.rend(); ++it) {
    if (const EncodedImage* image = image_at(it->utime)) {
      frame.tracks = &*it;
      frame.image = image;
      break;
    }
  }
  if (!frame.tracks) {
    if (!tracks_.empty() && (images_.empty() || tracks_.back().utime >= images_.back().utime)) {
      frame.tracks = &tracks_.back();  // drawn on a blank canvas
    } else if (!images_.empty()) {
      frame.image = &images_.back();  // no tracks (yet) for any buffered image
    }
  }
  frame.utime = frame.tracks ? frame.tracks->utime : frame.image ? frame.image->utime : 0;
  if (frame.tracks) frame.objects = objects_at(frame.tracks->utime);
  if (!frame.objects && !objects_.empty()) frame.objects = &objects_.back();
  return frame;
}

}  // namespace viewer
}  // namespace mbslam
