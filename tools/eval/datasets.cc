#include "tools/eval/datasets.h"

#include <yaml-cpp/yaml.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <set>
#include <sstream>

#include "common/util/atomic_file.h"
#include "tools/eval/point_metrics.h"

namespace mbslam {
namespace eval {
namespace {

namespace fs = std::filesystem;

bool IsDir(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

bool IsFile(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// Files in `dir` whose names end with `suffix`, sorted.
std::vector<std::string> ListFiles(const std::string& dir, const std::string& suffix) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      out.push_back(entry.path().string());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string Stem(const std::string& path) { return fs::path(path).stem().string(); }

}  // namespace

std::string DataRoot() {
  if (const char* env = std::getenv("MBSLAM_DATA"); env && *env) {
    return env;
  }
  std::string root = ".";
  if (const char* src = std::getenv("MBSLAM_SOURCE_DIR"); src && *src) {
    root = src;
  }
  return (fs::path(root) / ".." / "shared" / "data").lexically_normal().string();
}

std::string DataSetPath(const std::string& name) {
  const std::string path = (fs::path(DataRoot()) / name).string();
  return IsDir(path) ? path : "";
}

int TrackSet::NumGroups() const {
  return static_cast<int>(std::set<int>(labels.begin(), labels.end()).size());
}

Status ParseTracks(const std::string& text, TrackSet* set) {
  std::istringstream in(text);
  int points = 0, frames = 0;
  if (!(in >> points >> frames >> set->width >> set->height) || points < 0 || frames < 0) {
    return Status::Error("tracks: bad header (want 'P F width height')");
  }
  set->labels.assign(static_cast<size_t>(points), 0);
  for (int i = 0; i < points; ++i) {
    if (!(in >> set->labels[static_cast<size_t>(i)])) {
      return Status::Error("tracks: too few labels");
    }
  }
  set->tracks.assign(static_cast<size_t>(points),
                     std::vector<Eigen::Vector2d>(static_cast<size_t>(frames)));
  for (int i = 0; i < points; ++i) {
    for (int f = 0; f < frames; ++f) {
      std::string xs, ys;
      if (!(in >> xs >> ys)) {
        return Status::Error("tracks: point " + std::to_string(i) + " has fewer than " +
                             std::to_string(frames) + " positions");
      }
      // strtod reads "nan" as NaN.
      auto& p = set->tracks[static_cast<size_t>(i)][static_cast<size_t>(f)];
      char* end = nullptr;
      p.x() = std::strtod(xs.c_str(), &end);
      if (*end) {
        return Status::Error("tracks: bad number '" + xs + "'");
      }
      p.y() = std::strtod(ys.c_str(), &end);
      if (*end) {
        return Status::Error("tracks: bad number '" + ys + "'");
      }
    }
  }
  std::string extra;
  if (in >> extra) {
    return Status::Error("tracks: unexpected data after the last track");
  }
  return Status::Ok();
}

Status ReadTracksFile(const std::string& path, TrackSet* set) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text));
  std::string name = fs::path(path).filename().string();
  const std::string suffix = ".tracks.txt";
  if (name.size() > suffix.size() &&
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0) {
    name.resize(name.size() - suffix.size());
  }
  set->name = name;
  return ParseTracks(text, set).WithContext(path);
}

Status WriteTracksFile(const std::string& path, const TrackSet& set) {
  std::string text = std::to_string(set.num_points()) + " " + std::to_string(set.num_frames()) +
                     " " + std::to_string(set.width) + " " + std::to_string(set.height) + "\n";
  for (size_t i = 0; i < set.labels.size(); ++i) {
    text += (i ? " " : "") + std::to_string(set.labels[i]);
  }
  text += "\n";
  char buf[64];
  for (const auto& track : set.tracks) {
    for (size_t f = 0; f < track.size(); ++f) {
      if (std::isfinite(track[f].x()) && std::isfinite(track[f].y())) {
        std::snprintf(buf, sizeof(buf), "%s%.3f %.3f", f ? " " : "", track[f].x(), track[f].y());
      } else {
        std::snprintf(buf, sizeof(buf), "%snan nan", f ? " " : "");
      }
      text += buf;
    }
    text += "\n";
  }
  return WriteStringAtomically(path, text);
}

Status ReadTracksFolder(const std::string& dir, std::vector<TrackSet>* sets) {
  sets->clear();
  if (!IsDir(dir)) {
    return Status::Error("not a directory: " + dir);
  }
  for (const auto& path : ListFiles(dir, ".tracks.txt")) {
    TrackSet set;
    MBSLAM_RETURN_IF_ERROR(ReadTracksFile(path, &set));
    sets->push_back(std::move(set));
  }
  if (sets->empty()) {
    return Status::Error("no *.tracks.txt in " + dir);
  }
  return Status::Ok();
}

Status ReadLabelFile(const std::string& path, std::vector<int>* labels) {
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(path, &text));
  labels->clear();
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    if (token[0] == '#') {
      std::getline(in, token);
      continue;
    }
    char* end = nullptr;
    const long v = std::strtol(token.c_str(), &end, 10);
    if (*end) {
      return Status::Error(path + ": bad label '" + token + "'");
    }
    labels->push_back(static_cast<int>(v));
  }
  return Status::Ok();
}

Status WriteLabelFile(const std::string& path, const std::vector<int>& labels) {
  std::string text;
  for (size_t i = 0; i < labels.size(); ++i) {
    text += (i ? " " : "") + std::to_string(labels[i]);
  }
  return WriteStringAtomically(path, text + "\n");
}

Status ReadDavis(const std::string& root, std::vector<DavisSequence>* sequences) {
  sequences->clear();
  const std::string ann = (fs::path(root) / "Annotations").string();
  const std::string img = (fs::path(root) / "JPEGImages").string();
  if (!IsDir(ann)) {
    return Status::Error("DAVIS: no Annotations/ in " + root);
  }
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(ann, ec)) {
    if (entry.is_directory()) {
      names.push_back(entry.path().filename().string());
    }
  }
  std::sort(names.begin(), names.end());
  for (const auto& name : names) {
    DavisSequence seq;
    seq.name = name;
    for (const auto& mask : ListFiles((fs::path(ann) / name).string(), ".png")) {
      const std::string image = (fs::path(img) / name / (Stem(mask) + ".jpg")).string();
      if (!IsFile(image)) {
        return Status::Error("DAVIS: no image for mask " + mask);
      }
      seq.masks.push_back(mask);
      seq.images.push_back(image);
    }
    if (!seq.masks.empty()) {
      sequences->push_back(std::move(seq));
    }
  }
  if (sequences->empty()) {
    return Status::Error("DAVIS: no sequences in " + root);
  }
  return Status::Ok();
}

Status LoadBinaryMask(const std::string& path, cv::Mat* mask) {
  const cv::Mat raw = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (raw.empty()) {
    return Status::Error("cannot read mask " + path);
  }
  *mask = raw != 0;
  return Status::Ok();
}

Status ReadCamVid(const std::string& root, std::vector<CamVidFrame>* frames) {
  frames->clear();
  const std::string images = (fs::path(root) / "images").string();
  const std::string labels = (fs::path(root) / "labels").string();
  if (!IsDir(images) || !IsDir(labels)) {
    return Status::Error("CamVid: want images/ and labels/ in " + root);
  }
  for (const auto& label : ListFiles(labels, ".png")) {
    const std::string image = (fs::path(images) / fs::path(label).filename()).string();
    if (!IsFile(image)) {
      return Status::Error("CamVid: no image for " + label);
    }
    frames->push_back({image, label});
  }
  if (frames->empty()) {
    return Status::Error("CamVid: no labelled frames in " + root);
  }
  return Status::Ok();
}

bool IsCamVidStaticClass(int label) { return label >= kCamVidSky && label <= kCamVidFence; }
bool IsCamVidMovableClass(int label) { return label >= kCamVidCar && label <= kCamVidBicyclist; }

void CamVidFeatureStats::Add(const CamVidFeatureStats& o) {
  moving += o.moving;
  on_static += o.on_static;
  on_movable += o.on_movable;
  on_void += o.on_void;
  static_fraction = moving > 0 ? static_cast<double>(on_static) / moving : 0.0;
  movable_fraction = moving > 0 ? static_cast<double>(on_movable) / moving : 0.0;
}

CamVidFeatureStats CamVidMovingFeatureStats(const std::vector<LabelledFeature>& features,
                                            const cv::Mat& labels) {
  CamVidFeatureStats s;
  for (const auto& f : features) {
    if (!f.moving) {
      continue;
    }
    const int x = static_cast<int>(std::lround(f.u)), y = static_cast<int>(std::lround(f.v));
    if (x < 0 || y < 0 || x >= labels.cols || y >= labels.rows) {
      continue;
    }
    const int label = labels.at<uint8_t>(y, x);
    ++s.moving;
    if (IsCamVidStaticClass(label)) {
      ++s.on_static;
    } else if (IsCamVidMovableClass(label)) {
      ++s.on_movable;
    } else {
      ++s.on_void;
    }
  }
  s.Add(CamVidFeatureStats());  // computes the fractions
  return s;
}

Status ReadTumSubset(const std::string& root, TumSubset* subset) {
  *subset = TumSubset();
  MBSLAM_RETURN_IF_ERROR(
      ReadTumTrajectory((fs::path(root) / "truth_cam_poses.txt").string(), &subset->truth));
  const auto images = ListFiles((fs::path(root) / "raw_imgs").string(), "_rgb_raw.jpg");
  const auto depths = ListFiles((fs::path(root) / "depth_imgs").string(), "_depth_raw.png");
  if (images.size() != subset->truth.size()) {
    return Status::Error("TUM subset: " + std::to_string(images.size()) + " images but " +
                         std::to_string(subset->truth.size()) + " poses");
  }
  subset->images = images;
  subset->depths = depths;
  CameraIntrinsics& K = subset->intrinsics;
  K.name = "tum_fr3";
  K.width = 640;
  K.height = 480;
  K.fx = 535.4;
  K.fy = 539.2;
  K.cx = 320.1;
  K.cy = 247.6;
  return Status::Ok();
}

Status ReadTartanAirSubset(const std::string& root, int64_t frame_period_us,
                           TartanAirSubset* subset) {
  *subset = TartanAirSubset();
  MBSLAM_RETURN_IF_ERROR(ReadTartanAirPoses((fs::path(root) / "pose_left.txt").string(),
                                            frame_period_us, &subset->truth));
  subset->images = ListFiles((fs::path(root) / "images").string(), "_left.jpg");
  if (subset->images.size() != subset->truth.size()) {
    return Status::Error("TartanAir subset: " + std::to_string(subset->images.size()) +
                         " images but " + std::to_string(subset->truth.size()) + " poses");
  }
  CameraIntrinsics& K = subset->intrinsics;
  K.name = "tartanair";
  K.width = 640;
  K.height = 480;
  K.fx = K.fy = 320.0;
  K.cx = 320.0;
  K.cy = 240.0;
  return Status::Ok();
}

Status ReadSequenceFolder(const std::string& dir, SequenceFolder* seq) {
  *seq = SequenceFolder();
  const fs::path root(dir);
  MBSLAM_RETURN_IF_ERROR(
      LoadCameraIntrinsics((root / "calibration.yaml").string(), &seq->intrinsics));
  std::string text;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString((root / "timestamps.txt").string(), &text));
  std::istringstream in(text);
  int64_t index, utime;
  while (in >> index >> utime) {
    if (index != static_cast<int64_t>(seq->utimes.size())) {
      return Status::Error(dir + "/timestamps.txt: frame indices must count from 0");
    }
    seq->utimes.push_back(utime);
  }
  char name[32];
  for (size_t k = 0; k < seq->utimes.size(); ++k) {
    std::snprintf(name, sizeof(name), "%06zu", k);
    seq->images.push_back((root / "images" / (std::string(name) + ".png")).string());
    const std::string mask = (root / "masks" / (std::string(name) + ".png")).string();
    if (IsFile(mask)) {
      seq->masks.push_back(mask);
    }
    for (const char* ext : {".exr", ".png"}) {
      const std::string depth = (root / "depth" / (std::string(name) + ext)).string();
      if (IsFile(depth)) {
        seq->depths.push_back(depth);
        break;
      }
    }
  }
  if (IsFile((root / "cam_trajectory.tum").string())) {
    MBSLAM_RETURN_IF_ERROR(ReadTumTrajectory((root / "cam_trajectory.tum").string(), &seq->camera));
  }
  const std::string objects_yaml = (root / "objects.yaml").string();
  if (IsFile(objects_yaml)) {
    YAML::Node node;
    try {
      node = YAML::LoadFile(objects_yaml);
    } catch (const YAML::Exception& e) {
      return Status::Error(objects_yaml + ": " + e.what());
    }
    for (const auto& o : node["objects"]) {
      BodyTruth body;
      try {
        body.id = o["id"].as<int>();
        body.name = o["name"].as<std::string>();
        for (int i = 0; i < 3; ++i) {
          body.extent[i] = o["extent"][i].as<double>();
        }
      } catch (const YAML::Exception& e) {
        return Status::Error(objects_yaml + ": " + e.what());
      }
      MBSLAM_RETURN_IF_ERROR(ReadTumTrajectory(
          (root / "objects" / (std::to_string(body.id) + ".tum")).string(), &body.poses));
      seq->bodies[body.id] = std::move(body);
    }
  }
  const std::string points_dir = (root / "points").string();
  if (IsDir(points_dir)) {
    for (const auto& path : ListFiles(points_dir, ".txt")) {
      const std::string stem = Stem(path);
      char* end = nullptr;
      const long id = std::strtol(stem.c_str(), &end, 10);
      if (*end) {
        continue;  // not a body id
      }
      MBSLAM_RETURN_IF_ERROR(ReadPointsFile(path, &seq->points[static_cast<int>(id)]));
    }
  }
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
