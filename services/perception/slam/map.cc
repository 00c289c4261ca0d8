#include "services/perception/slam/map.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <string>

#include "common/util/atomic_file.h"

namespace mbslam {

int64_t Map::AddKeyframe(Keyframe keyframe) {
  keyframe.id = next_keyframe_id_++;
  const int64_t id = keyframe.id;
  keyframes_[id] = std::move(keyframe);
  return id;
}

int64_t Map::AddPoint(MapPoint point) {
  point.id = next_point_id_++;
  const int64_t id = point.id;
  if (point.track_id >= 0) point_of_track_[point.track_id] = id;
  points_[id] = std::move(point);
  return id;
}

void Map::AddObservation(int64_t point_id, int64_t keyframe_id, const Eigen::Vector2d& xy) {
  MapPoint* p = point(point_id);
  Keyframe* k = keyframe(keyframe_id);
  if (!p || !k) return;
  for (const Observation& o : p->observations) {
    if (o.keyframe_id == keyframe_id) return;
  }
  p->observations.push_back(Observation{keyframe_id, xy});
  k->point_ids.push_back(point_id);
}

void Map::RemovePoint(int64_t point_id) {
  auto it = points_.find(point_id);
  if (it == points_.end()) return;
  for (const Observation& o : it->second.observations) {
    Keyframe* k = keyframe(o.keyframe_id);
    if (!k) continue;
    k->point_ids.erase(std::remove(k->point_ids.begin(), k->point_ids.end(), point_id), k->point_ids.end());
  }
  if (it->second.track_id >= 0) {
    auto t = point_of_track_.find(it->second.track_id);
    if (t != point_of_track_.end() && t->second == point_id) point_of_track_.erase(t);
  }
  points_.erase(it);
}

int Map::RemoveStalePoints(int64_t seen_before_frame) {
  std::vector<int64_t> stale;
  for (const auto& [id, p] : points_) {
    if (p.observations.size() >= 2) continue;
    if (p.track_id < 0 || p.last_seen_frame < seen_before_frame) stale.push_back(id);
  }
  for (int64_t id : stale) RemovePoint(id);
  return static_cast<int>(stale.size());
}

void Map::Clear() {
  keyframes_.clear();
  points_.clear();
  point_of_track_.clear();
}

MapPoint* Map::point(int64_t id) {
  auto it = points_.find(id);
  return it == points_.end() ? nullptr : &it->second;
}
const MapPoint* Map::point(int64_t id) const {
  auto it = points_.find(id);
  return it == points_.end() ? nullptr : &it->second;
}
Keyframe* Map::keyframe(int64_t id) {
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : &it->second;
}
const Keyframe* Map::keyframe(int64_t id) const {
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : &it->second;
}

int64_t Map::PointOfTrack(int64_t track_id) const {
  auto it = point_of_track_.find(track_id);
  return it == point_of_track_.end() ? -1 : it->second;
}

void Map::AssociateTrack(int64_t point_id, int64_t track_id) {
  MapPoint* p = point(point_id);
  if (!p) return;
  if (p->track_id >= 0) point_of_track_.erase(p->track_id);
  p->track_id = track_id;
  point_of_track_[track_id] = point_id;
}

void Map::ReleaseTrack(int64_t track_id) {
  auto it = point_of_track_.find(track_id);
  if (it == point_of_track_.end()) return;
  if (MapPoint* p = point(it->second)) p->track_id = -1;
  point_of_track_.erase(it);
}

const Keyframe* Map::LastKeyframe() const {
  return keyframes_.empty() ? nullptr : &keyframes_.rbegin()->second;
}

void Map::Rescale(double s) {
  for (auto& [id, k] : keyframes_) k.cam_from_world.translation *= s;
  for (auto& [id, p] : points_) p.position *= s;
}

namespace {

std::string HexOf(const uint8_t* bytes, size_t n) {
  static const char* kDigits = "0123456789abcdef";
  std::string hex(2 * n, '0');
  for (size_t i = 0; i < n; ++i) {
    hex[2 * i] = kDigits[bytes[i] >> 4];
    hex[2 * i + 1] = kDigits[bytes[i] & 15];
  }
  return hex;
}

bool BytesOfHex(const std::string& hex, uint8_t* bytes, size_t n) {
  if (hex.size() != 2 * n) return false;
  auto nibble = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  for (size_t i = 0; i < n; ++i) {
    const int hi = nibble(hex[2 * i]), lo = nibble(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) return false;
    bytes[i] = static_cast<uint8_t>(hi * 16 + lo);
  }
  return true;
}

constexpr int kMaxPatchSide = 63;  // larger patches in a file are refused (px)
constexpr int kMinPatchSide =
    5;  // ... and smaller ones or even sides: a patch is centred on its point
constexpr int64_t kMaxId = int64_t{1} << 62;  // ids at or above are refused (the next id must fit)

}  // namespace

Status Map::Save(const std::string& path) const {
  return WriteFileAtomically(path, [this](std::ostream& out) {
    out << std::setprecision(17);
    out << "mbslam_map 2\n";
    out << "keyframes " << keyframes_.size() << "\n";
    for (const auto& [id, k] : keyframes_) {
      const Rigid3d& T = k.cam_from_world;
      out << id << " " << k.frame_index << " " << k.utime << " " << T.rotation.w() << " "
          << T.rotation.x() << " " << T.rotation.y() << " " << T.rotation.z() << " "
          << T.translation.x() << " " << T.translation.y() << " " << T.translation.z() << " "
          << (k.fixed ? 1 : 0) << "\n";
    }
    out << "points " << points_.size() << "\n";
    std::vector<int64_t> ids;
    for (const auto& kv : points_) ids.push_back(kv.first);
    std::sort(ids.begin(), ids.end());
    for (int64_t id : ids) {
      const MapPoint& p = points_.at(id);
      out << id << " " << p.position.x() << " " << p.position.y() << " " << p.position.z() << " "
          << static_cast<int>(p.gray) << " " << p.observations.size();
      for (const Observation& o : p.observations) out << " " << o.keyframe_id << " " << o.xy.x() << " " << o.xy.y();
      out << " "
          << (p.has_descriptor ? HexOf(p.descriptor.bits.data(), p.descriptor.bits.size())
                               : std::string("-"));
      const bool patch = !p.patch.empty() && p.patch.type() == CV_8UC1 &&
                         p.patch.rows == p.patch.cols && p.patch.rows >= kMinPatchSide &&
                         p.patch.rows <= kMaxPatchSide && p.patch.rows % 2 == 1 &&
                         p.patch.isContinuous();
      if (patch) {
        out << " " << p.patch.rows << " " << HexOf(p.patch.ptr<uint8_t>(0), p.patch.total());
      } else {
        out << " 0";
      }
      out << "\n";
    }
    return static_cast<bool>(out);
  });
}

Status Map::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return Status::Error("cannot open map " + path);
  std::string magic;
  int version = 0;
  in >> magic >> version;
  if (magic != "mbslam_map" || (version != 1 && version != 2))
    return Status::Error(path + ": not an mbslam map");
  Map loaded;
  std::string word;
  size_t n = 0;
  in >> word >> n;
  if (word != "keyframes" || n > 10000000) return Status::Error(path + ": bad keyframe header");
  for (size_t i = 0; i < n; ++i) {
    Keyframe k;
    double qw, qx, qy, qz, tx, ty, tz;
    int fixed = 0;
    if (!(in >> k.id >> k.frame_index >> k.utime >> qw >> qx >> qy >> qz >> tx >> ty >> tz >> fixed)) {
      return Status::Error(path + ": truncated keyframe");
    }
    const Eigen::Quaterniond q(qw, qx, qy, qz);
    const Eigen::Vector3d t(tx, ty, tz);
    if (!q.coeffs().allFinite() || !t.allFinite() || std::abs(q.norm() - 1.0) > 1e-3) {
      return Status::Error(path + ": keyframe " + std::to_string(k.id) + " has a bad pose");
    }
    if (k.id < 0 || k.id >= kMaxId)
      return Status::Error(path + ": bad keyframe id " + std::to_string(k.id));
    if (loaded.keyframes_.count(k.id)) {
      return Status::Error(path + ": keyframe " + std::to_string(k.id) + " twice");
    }
    k.cam_from_world = Rigid3d(q.normalized(), t);
    k.fixed = fixed != 0;
    loaded.next_keyframe_id_ = std::max(loaded.next_keyframe_id_, k.id + 1);
    loaded.keyframes_[k.id] = std::move(k);
  }
  in >> word >> n;
  if (word != "points" || n > 100000000) return Status::Error(path + ": bad point header");
  for (size_t i = 0; i < n; ++i) {
    MapPoint p;
    int gray = 0;
    size_t nobs = 0;
    if (!(in >> p.id >> p.position.x() >> p.position.y() >> p.position.z() >> gray >> nobs) || nobs > 100000) {
      return Status::Error(path + ": truncated point");
    }
    if (!p.position.allFinite() || gray < 0 || gray > 255) {
      return Status::Error(path + ": point " + std::to_string(p.id) +
                           " is not finite or has a bad grey level");
    }
    if (p.id < 0 || p.id >= kMaxId)
      return Status::Error(path + ": bad point id " + std::to_string(p.id));
    if (loaded.points_.count(p.id)) {
      return Status::Error(path + ": point " + std::to_string(p.id) + " twice");
    }
    p.gray = static_cast<uint8_t>(gray);
    for (size_t j = 0; j < nobs; ++j) {
      Observation o;
      if (!(in >> o.keyframe_id >> o.xy.x() >> o.xy.y())) return Status::Error(path + ": truncated observation");
      Keyframe* k = loaded.keyframe(o.keyframe_id);
      const bool repeated =
          std::any_of(p.observations.begin(), p.observations.end(),
                      [&o](const Observation& seen) { return seen.keyframe_id == o.keyframe_id; });
      if (!k || !o.xy.allFinite() || repeated) {
        return Status::Error(path + ": point " + std::to_string(p.id) + " has a bad observation");
      }
      p.observations.push_back(o);
      k->point_ids.push_back(p.id);
    }
    if (version >= 2) {
      std::string hex;
      if (!(in >> hex)) return Status::Error(path + ": truncated point descriptor");
      if (hex != "-") {
        if (!BytesOfHex(hex, p.descriptor.bits.data(), p.descriptor.bits.size())) {
          return Status::Error(path + ": point " + std::to_string(p.id) + " has a bad descriptor");
        }
        p.has_descriptor = true;
      }
      int side = 0;
      if (!(in >> side)) return Status::Error(path + ": truncated point patch");
      const bool bad_side =
          side < 0 || side > kMaxPatchSide || (side > 0 && (side < kMinPatchSide || side % 2 == 0));
      if (bad_side) {
        return Status::Error(path + ": point " + std::to_string(p.id) + " has a bad patch size");
      }
      if (side > 0) {
        p.patch.create(side, side, CV_8UC1);
        if (!(in >> hex) || !BytesOfHex(hex, p.patch.ptr<uint8_t>(0), p.patch.total())) {
          return Status::Error(path + ": point " + std::to_string(p.id) + " has a bad patch");
        }
      }
    }
    loaded.next_point_id_ = std::max(loaded.next_point_id_, p.id + 1);
    loaded.points_[p.id] = std::move(p);
  }
  *this = std::move(loaded);
  return Status::Ok();
}

size_t Map::num_described_points() const {
  size_t n = 0;
  for (const auto& [id, p] : points_) n += p.has_descriptor ? 1 : 0;
  return n;
}

}  // namespace mbslam
