// Reader of the simulator's sequence folder (tools/sim/SEQUENCE_FORMAT.md).

#include <yaml-cpp/yaml.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "common/config/options_yaml.h"
#include "common/util/time.h"
#include "drivers/camera/image_list_source.h"
#include "drivers/common/pose_files.h"
#include "services/perception/geometry/pose_buffer.h"

namespace mbslam {
namespace fs = std::filesystem;
namespace {

struct ObjectTrack {
  int id = 0;
  std::string name;
  Eigen::Vector3d extent = Eigen::Vector3d::Zero();
  std::vector<TimedPose> samples;
};

std::string FrameFileName(int64_t index, const char* ext) {
  char name[64];
  std::snprintf(name, sizeof(name), "%06lld%s", static_cast<long long>(index), ext);
  return name;
}

// Pose and finite-difference velocities (world frame) at `utime`; false when the
// object has no sample around that time.
bool ObjectStateAt(const ObjectTrack& track, int64_t utime, int64_t max_gap_us, BodyTruth* body) {
  const std::vector<TimedPose>& s = track.samples;
  if (s.empty() || utime < s.front().utime || utime > s.back().utime) return false;
  auto upper = std::lower_bound(s.begin(), s.end(), utime,
                                [](const TimedPose& p, int64_t t) { return p.utime < t; });
  size_t a, b;
  const size_t k = static_cast<size_t>(upper - s.begin());
  if (upper->utime == utime) {
    body->world_from_body = upper->pose;
    a = k > 0 ? k - 1 : k;
    b = k + 1 < s.size() ? k + 1 : k;
  } else {
    a = k - 1;
    b = k;
    if (s[b].utime - s[a].utime > max_gap_us) return false;
    const double f = static_cast<double>(utime - s[a].utime) /
                     static_cast<double>(s[b].utime - s[a].utime);
    body->world_from_body = Rigid3d::Interpolate(s[a].pose, s[b].pose, f);
  }
  if (a != b) {
    const double dt = UtimeToSeconds(s[b].utime - s[a].utime);
    body->linear_velocity = (s[b].pose.translation - s[a].pose.translation) / dt;
    body->angular_velocity =
        LogSO3(s[b].pose.RotationMatrix() * s[a].pose.RotationMatrix().transpose()) / dt;
  }
  body->id = track.id;
  body->name = track.name;
  body->extent = track.extent;
  return true;
}

// objects.yaml: a list (or {objects: [...]}) of {id, name | class, extent: [x, y, z], ...}.
SourceStatus ReadObjectsYaml(const std::string& path, std::map<int, ObjectTrack>* tracks) {
  YAML::Node root;
  const Status st = ReadYamlFile(path, &root);
  if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
  YAML::Node list = root;
  if (root.IsMap() && root["objects"]) list = root["objects"];
  if (root.IsNull()) return SourceStatus::Ok();
  if (!list.IsSequence()) {
    return SourceStatus::Error(SourceError::kConfig, path + ": expected a list of objects");
  }
  try {
    for (const YAML::Node& o : list) {
      if (!o["id"]) return SourceStatus::Error(SourceError::kConfig, path + ": object without id");
      ObjectTrack& t = (*tracks)[o["id"].as<int>()];
      t.id = o["id"].as<int>();
      if (o["name"]) {
        t.name = o["name"].as<std::string>();
      } else if (o["class"]) {
        t.name = o["class"].as<std::string>();
      }
      if (o["extent"]) {
        const std::vector<double> e = o["extent"].as<std::vector<double>>();
        if (e.size() != 3) {
          return SourceStatus::Error(SourceError::kConfig, path + ": extent needs 3 values");
        }
        t.extent = Eigen::Vector3d(e[0], e[1], e[2]);
      }
    }
  } catch (const YAML::Exception& e) {
    return SourceStatus::Error(SourceError::kConfig, path + ": " + e.what());
  }
  return SourceStatus::Ok();
}

std::string ScenarioName(const std::string& dir) {
  const std::string path = (fs::path(dir) / "scenario.yaml").string();
  YAML::Node root;
  if (ReadYamlFile(path, &root).ok() && root.IsMap()) {
    try {
      for (const char* key : {"scenario", "name"}) {
        if (root[key] && root[key].IsScalar()) return root[key].as<std::string>();
      }
    } catch (const YAML::Exception&) {
    }
  }
  return fs::absolute(dir).lexically_normal().filename().string();
}

}  // namespace

SourceStatus IndexSimSequence(const std::string& dir, double max_gap_s, ImageIndex* index) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return SourceStatus::Error(SourceError::kNotFound, "no folder " + dir);
  const fs::path root(dir);
  const std::string stamps = (root / "timestamps.txt").string();
  std::ifstream in(stamps);
  if (!in) {
    return SourceStatus::Error(SourceError::kNotFound,
                               dir + " is not a sequence folder (no timestamps.txt)");
  }
  index->entries.clear();
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::vector<std::string> f = SplitFields(line);
    if (f.empty() || f[0][0] == '#') continue;
    const std::string where = stamps + ":" + std::to_string(number);
    long long frame = 0, utime = 0;
    char extra = 0;
    if (f.size() != 2 || std::sscanf(f[0].c_str(), "%lld%c", &frame, &extra) != 1 ||
        std::sscanf(f[1].c_str(), "%lld%c", &utime, &extra) != 1) {
      return SourceStatus::Error(SourceError::kConfig, where + ": expected '<index> <utime>'");
    }
    if (frame != static_cast<long long>(index->entries.size())) {
      return SourceStatus::Error(SourceError::kConfig,
                                 where + ": frame index " + std::to_string(frame) +
                                     ", expected " + std::to_string(index->entries.size()));
    }
    ImageEntry e;
    e.utime = utime;
    e.path = (root / "images" / FrameFileName(frame, ".png")).string();
    const fs::path mask = root / "masks" / FrameFileName(frame, ".png");
    if (fs::is_regular_file(mask, ec)) e.mask_path = mask.string();
    if (!index->entries.empty() && e.utime <= index->entries.back().utime) {
      return SourceStatus::Error(SourceError::kConfig, where + ": time does not increase");
    }
    index->entries.push_back(e);
  }
  if (index->entries.empty()) {
    return SourceStatus::Error(SourceError::kNotFound, stamps + " lists no frames");
  }
  const std::string calibration = (root / "calibration.yaml").string();
  if (fs::is_regular_file(calibration, ec)) index->calibration_file = calibration;
  const std::string scenario = ScenarioName(dir);
  index->description = "sequence " + dir + " (" + scenario + ", " +
                       std::to_string(index->entries.size()) + " frames)";

  const int64_t max_gap_us = SecondsToUtime(max_gap_s);
  const std::string trajectory = (root / "cam_trajectory.tum").string();
  if (fs::is_regular_file(trajectory, ec)) {
    SourceStatus st = AttachGroundTruth(trajectory, "tum", max_gap_s, "sim:" + scenario, index);
    if (!st.ok()) return st;
  }

  std::map<int, ObjectTrack> tracks;
  const fs::path objects_dir = root / "objects";
  if (fs::is_directory(objects_dir, ec)) {
    for (fs::directory_iterator it(objects_dir, ec), end; !ec && it != end; it.increment(ec)) {
      if (it->path().extension() != ".tum") continue;
      const std::string stem = it->path().stem().string();
      int id = 0;
      char extra = 0;
      if (std::sscanf(stem.c_str(), "%d%c", &id, &extra) != 1) continue;
      ObjectTrack& t = tracks[id];
      t.id = id;
      const Status st = ReadTumTrajectory(it->path().string(), &t.samples);
      if (!st.ok()) return SourceStatus::Error(SourceError::kConfig, st.message());
    }
    const std::string objects_yaml = (root / "objects.yaml").string();
    if (fs::is_regular_file(objects_yaml, ec)) {
      SourceStatus st = ReadObjectsYaml(objects_yaml, &tracks);
      if (!st.ok()) return st;
    }
  }
  if (!tracks.empty()) {
    index->has_truth = true;
    index->truth_source = "sim:" + scenario;
    for (ImageEntry& e : index->entries) {
      for (const auto& [id, track] : tracks) {
        BodyTruth body;
        if (ObjectStateAt(track, e.utime, max_gap_us, &body)) e.bodies.push_back(body);
      }
    }
  }
  return SourceStatus::Ok();
}

}  // namespace mbslam
