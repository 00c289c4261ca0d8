#include "services/perception/occupancy/occupancy_map.h"

#include <octomap/OcTree.h>

#include <algorithm>
#include <cmath>
#include <unordered_set>
#include <utility>

#include "common/util/atomic_file.h"
#include "common/util/logging.h"
#include "services/perception/occupancy/octree_ops.h"

namespace mbslam {
namespace {

// Shortest ray that is still a measurement (map units): an end point at the camera
// centre has no direction.
constexpr double kMinRayLength = 1e-9;

octomap::point3d ToOcto(const Eigen::Vector3d& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()),
                          static_cast<float>(p.z()));
}

}  // namespace

const char* OccupancyUnitsName(OccupancyMap::Units units) {
  return units == OccupancyMap::Units::kMetres ? "metres" : "up-to-scale";
}

OccupancyMap::OccupancyMap(const OccupancyMapOptions& options, Units units)
    : options_(options), units_(units) {
  if (!options_.Check()) {
    MBSLAM_LOG(WARNING) << "occupancy: " << LastOptionError() << "; using the defaults";
    options_ = OccupancyMapOptions();
  }
  weak_hit_log_odds_ = static_cast<float>(std::log(options_.dense.prob_hit / (1.0 - options_.dense.prob_hit)));
  if (units_ == Units::kMetres || options_.resolution_depth_fraction <= 0.0) {
    double resolution = 0.0, max_range = 0.0;
    MetricResolution(&resolution, &max_range);
    Rebuild(resolution, max_range);
  }
}

OccupancyMap::~OccupancyMap() = default;

void OccupancyMap::MetricResolution(double* resolution, double* max_range) const {
  *resolution = options_.resolution_m;
  *max_range = options_.max_range_m > 0.0 ? options_.max_range_m : -1.0;
}

double OccupancyMap::resolution() const { return tree_ ? tree_->getResolution() : 0.0; }

OccupancyInsertSummary OccupancyMap::InsertRays(
    const Eigen::Vector3d& camera_center_in_world,
    const std::vector<Eigen::Vector3d>& points_in_world,
    const std::vector<Eigen::Vector3d>& interpolated_in_world) {
  OccupancyInsertSummary summary;
  if (!camera_center_in_world.allFinite()) {
    summary.rays_rejected = static_cast<int>(points_in_world.size());
    summary.interpolated_rejected = static_cast<int>(interpolated_in_world.size());
    return summary;
  }
  RayBatch batch;
  batch.origin = camera_center_in_world;
  batch.ends.reserve(points_in_world.size());
  for (const Eigen::Vector3d& p : points_in_world) {
    if (!p.allFinite() || (p - camera_center_in_world).norm() < kMinRayLength) {
      ++summary.rays_rejected;
      continue;
    }
    batch.ends.push_back(p.cast<float>());
  }
  batch.interpolated.reserve(interpolated_in_world.size());
  for (const Eigen::Vector3d& p : interpolated_in_world) {
    if (!p.allFinite() || (p - camera_center_in_world).norm() < kMinRayLength) {
      ++summary.interpolated_rejected;
      continue;
    }
    batch.interpolated.push_back(p.cast<float>());
  }
  if (batch.ends.empty() && batch.interpolated.empty()) {
    return summary;
  }

  if (!tree_) {
    // Up to scale, resolution not fixed yet: collect rays until their median length
    // is known, then build the tree from all of them.
    summary.rays_buffered = static_cast<int>(batch.ends.size());
    stored_rays_ += static_cast<int64_t>(batch.size());
    buffered_measured_rays_ += summary.rays_buffered;
    batches_.push_back(std::move(batch));
    if (buffered_measured_rays_ >= options_.min_rays_for_resolution) {
      const double median = MedianStoredRayLength();
      const double resolution = options_.resolution_depth_fraction * median;
      const double max_range = options_.max_range_depth_multiple > 0.0
                                   ? options_.max_range_depth_multiple * median
                                   : (options_.max_range_m > 0.0 ? options_.max_range_m : -1.0);
      if (resolution > 0.0 && std::isfinite(resolution)) {
        MBSLAM_LOG(INFO) << "occupancy: median ray length " << median << " map units: voxel edge "
                         << resolution << ", range bound " << max_range;
        Rebuild(resolution, max_range);
        summary.rays_inserted = static_cast<int>(buffered_measured_rays_);
        StoreBatch(RayBatch());  // applies the bound on stored rays
        ++revision_;
      }
    }
    return summary;
  }

  InsertBatch(batch, &summary);
  const Eigen::Vector3d origin = batch.origin;
  if (options_.max_stored_rays > 0) {
    StoreBatch(std::move(batch));
  }
  BoundMemory(origin);
  ++revision_;
  return summary;
}

namespace {

// OctoMap's coordToKeyChecked converts resolution_factor * coordinate to int before it
// checks the range, which is undefined behaviour for points far outside the tree (UBSan:
// "1e+10 is outside the range of representable values of type 'int'"). Coordinates
// outside the tree's 2^15 voxels per side, and NaN, are refused here first.
bool KeyInTree(const octomap::OcTree& tree, const octomap::point3d& p, octomap::OcTreeKey& key) {
  const double limit = tree.getResolution() * 32768.0;
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(static_cast<double>(p(i))) < limit)) return false;
  }
  return tree.coordToKeyChecked(p, key);
}

}  // namespace

void OccupancyMap::InsertBatch(const RayBatch& batch, OccupancyInsertSummary* summary) {
  // OctoMap's insertPointCloud (computeUpdate / computeDiscreteUpdate, then one update
  // per voxel, occupied before free), with the update step done in one depth-first walk
  // (octree_ops.h). Coordinates outside the tree's range are rejected here instead of
  // letting OctoMap print a warning per ray.
  const octomap::point3d origin = ToOcto(batch.origin);
  octomap::OcTreeKey key;
  if (!KeyInTree(*tree_, origin, key)) {
    summary->rays_rejected += static_cast<int>(batch.ends.size());
    return;
  }
  std::vector<octomap::point3d> ends;
  ends.reserve(batch.ends.size());
  std::unordered_set<octomap::OcTreeKey, octomap::OcTreeKey::KeyHash> end_voxels;
  for (const Eigen::Vector3f& e : batch.ends) {
    const octomap::point3d p(e.x(), e.y(), e.z());
    // Discretised: one ray per end voxel, to its centre (points outside the tree's
    // range go on as they are and are rejected below).
    if (options_.discretize && KeyInTree(*tree_, p, key)) {
      if (end_voxels.insert(key).second) {
        ends.push_back(tree_->keyToCoord(key));
      } else {
        ++summary->rays_inserted;  // merged into an earlier ray to the same voxel
      }
      continue;
    }
    ends.push_back(p);
  }
  if (!key_ray_) {
    key_ray_ = std::make_unique<octomap::KeyRay>();
  }
  updates_.clear();
  for (const octomap::point3d& p : ends) {
    if (max_range_ < 0.0 || (p - origin).norm() <= max_range_) {
      octomap::OcTreeKey end_key;
      if (!KeyInTree(*tree_, p, end_key)) {
        ++summary->rays_rejected;
        continue;
      }
      if (tree_->computeRayKeys(origin, p, *key_ray_)) {
        for (const octomap::OcTreeKey& k : *key_ray_) {
          updates_.push_back(VoxelUpdate(k, false));
        }
      }
      updates_.push_back(VoxelUpdate(end_key, true));
    } else {
      const octomap::point3d direction = (p - origin).normalized();
      const octomap::point3d last = origin + direction * static_cast<float>(max_range_);
      if (!KeyInTree(*tree_, last, key)) {
        ++summary->rays_rejected;
        continue;
      }
      if (tree_->computeRayKeys(origin, last, *key_ray_)) {
        for (const octomap::OcTreeKey& k : *key_ray_) {
          updates_.push_back(VoxelUpdate(k, false));
        }
      }
      ++summary->rays_truncated;
    }
    ++summary->rays_inserted;
  }
  // Interpolated end points: one ray per end voxel (to the first point in it), a weak
  // hit there, free space on the way when asked; none beyond the range bound.
  ends_by_voxel_.clear();
  for (size_t i = 0; i < batch.interpolated.size(); ++i) {
    const Eigen::Vector3f& e = batch.interpolated[i];
    const octomap::point3d p(e.x(), e.y(), e.z());
    octomap::OcTreeKey end_key;
    if ((max_range_ >= 0.0 && (p - origin).norm() > max_range_) || !KeyInTree(*tree_, p, end_key)) {
      ++summary->interpolated_rejected;
      continue;
    }
    ends_by_voxel_.emplace_back(WeakHitVoxelUpdate(end_key), static_cast<uint32_t>(i));
  }
  std::sort(ends_by_voxel_.begin(), ends_by_voxel_.end());  // per voxel, the first point first
  for (size_t n = 0; n < ends_by_voxel_.size(); ++n) {
    if (n > 0 && ends_by_voxel_[n].first == ends_by_voxel_[n - 1].first) {
      ++summary->interpolated_merged;
      continue;
    }
    if (options_.dense.free_space) {
      const Eigen::Vector3f& e = batch.interpolated[ends_by_voxel_[n].second];
      if (tree_->computeRayKeys(origin, octomap::point3d(e.x(), e.y(), e.z()), *key_ray_)) {
        for (const octomap::OcTreeKey& k : *key_ray_) {
          updates_.push_back(VoxelUpdate(k, false));
        }
      }
    }
    updates_.push_back(ends_by_voxel_[n].first);
    ++summary->interpolated_inserted;
  }
  num_occupied_ += ApplyVoxelUpdates(tree_.get(), &updates_, weak_hit_log_odds_);
}

void OccupancyMap::StoreBatch(RayBatch batch) {
  stored_rays_ += static_cast<int64_t>(batch.size());
  if (batch.size() > 0) {
    batches_.push_back(std::move(batch));
  }
  while (!batches_.empty() && stored_rays_ > options_.max_stored_rays) {
    const int64_t n = static_cast<int64_t>(batches_.front().size());
    stored_rays_ -= n;
    rays_forgotten_ += n;
    batches_.pop_front();
  }
}

namespace {
// Each node is a 16-byte allocation (32 with glibc's header and alignment); an inner
// node also holds an array of 8 child pointers (80 bytes allocated), and in these trees
// about one node in four is inner (occupancy_map_test checks the estimate).
constexpr int64_t kBytesPerNode = 32 + 80 / 4;
}  // namespace

int64_t OccupancyMap::MemoryBytes() const {
  if (!tree_) return 0;
  return static_cast<int64_t>(tree_->size()) * kBytesPerNode;
}

void OccupancyMap::BoundMemory(const Eigen::Vector3d& center) {
  if (!tree_ || options_.max_memory_mb <= 0.0) return;
  const double limit = options_.max_memory_mb * 1024.0 * 1024.0;
  if (static_cast<double>(MemoryBytes()) <= limit) return;
  octomap::OcTreeKey c;
  if (!KeyInTree(*tree_, ToOcto(center), c)) return;
  const double res = tree_->getResolution();
  const int64_t occupied_before = num_occupied_;
  auto box = [&c](int half, octomap::OcTreeKey* lo, octomap::OcTreeKey* hi) {
    for (int i = 0; i < 3; ++i) {
      (*lo)[i] = static_cast<octomap::key_type>(std::max(0, static_cast<int>(c[i]) - half));
      (*hi)[i] = static_cast<octomap::key_type>(std::min(65535, static_cast<int>(c[i]) + half));
    }
  };
  // The largest box (halving from keep_half_edge_voxels) whose copy is below half the
  // bound, found by counting (a third of the cost of a copy), then one copy.
  int half = options_.keep_half_edge_voxels;
  octomap::OcTreeKey lo, hi;
  while (true) {
    box(half, &lo, &hi);
    if (half <= 1 || static_cast<double>(CountCropNodes(*tree_, lo, hi)) * kBytesPerNode <= 0.5 * limit) break;
    half /= 2;
  }
  int64_t occupied = 0;
  tree_ = CropOctree(*tree_, lo, hi, &occupied);
  num_occupied_ = occupied;
  // Stored rays from outside the box would bring the dropped voxels back on a rebuild.
  const double reach = (half + 0.5) * res;
  for (auto it = batches_.begin(); it != batches_.end();) {
    if (((it->origin - center).cwiseAbs().array() > reach).any()) {
      stored_rays_ -= static_cast<int64_t>(it->size());
      rays_forgotten_ += static_cast<int64_t>(it->size());
      it = batches_.erase(it);
    } else {
      ++it;
    }
  }
  ++crops_;
  occupied_dropped_ += std::max<int64_t>(0, occupied_before - num_occupied_);
  MBSLAM_LOG(INFO) << "occupancy: memory bound of " << options_.max_memory_mb << " MB reached; kept the "
                   << 2 * half + 1 << " voxel box around the camera (" << tree_->size() << " nodes, "
                   << occupied_before - num_occupied_ << " occupied voxels dropped)";
}

double OccupancyMap::MedianStoredRayLength() const {
  std::vector<double> lengths;
  lengths.reserve(static_cast<size_t>(stored_rays_));
  for (const RayBatch& batch : batches_) {
    const Eigen::Vector3f origin = batch.origin.cast<float>();
    for (const Eigen::Vector3f& end : batch.ends) {
      lengths.push_back((end - origin).norm());
    }
  }
  if (lengths.empty()) {
    return 0.0;
  }
  auto mid = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), mid, lengths.end());
  return *mid;
}

void OccupancyMap::Rebuild(double resolution, double max_range) {
  tree_ = std::make_unique<octomap::OcTree>(resolution);
  tree_->setProbHit(options_.prob_hit);
  tree_->setProbMiss(options_.prob_miss);
  tree_->setClampingThresMin(options_.clamping_min);
  tree_->setClampingThresMax(options_.clamping_max);
  tree_->setOccupancyThres(options_.occupancy_threshold);
  max_range_ = max_range;
  num_occupied_ = 0;
  OccupancyInsertSummary ignored;
  for (const RayBatch& batch : batches_) {
    InsertBatch(batch, &ignored);
  }
}

Status OccupancyMap::Rescale(double factor, Units units) {
  if (!std::isfinite(factor) || factor <= 0.0) {
    return Status::Error("occupancy: rescale factor must be finite and > 0 (got " +
                         std::to_string(factor) + ")");
  }
  const float f = static_cast<float>(factor);
  for (RayBatch& batch : batches_) {
    batch.origin *= factor;
    for (Eigen::Vector3f& end : batch.ends) {
      end *= f;
    }
    for (Eigen::Vector3f& end : batch.interpolated) {
      end *= f;
    }
  }
  units_ = units;
  if (units == Units::kMetres) {
    double resolution = 0.0, max_range = 0.0;
    MetricResolution(&resolution, &max_range);
    Rebuild(resolution, max_range);
  } else if (tree_) {
    Rebuild(tree_->getResolution() * factor, max_range_ > 0.0 ? max_range_ * factor : max_range_);
  }
  if (tree_ && !batches_.empty()) {
    BoundMemory(batches_.back().origin);
  }
  if (tree_) {
    StoreBatch(RayBatch());  // the bound applies once the tree exists
  }
  ++revision_;
  return Status::Ok();
}

Status OccupancyMap::Serialize(std::string* binary) const {
  if (!tree_) {
    return Status::Error("occupancy: map not started yet (" + std::to_string(stored_rays_) +
                         " of " + std::to_string(options_.min_rays_for_resolution) +
                         " rays needed to fix the voxel size of an up-to-scale map)");
  }
  binary->clear();
  WriteOctreeBinary(*tree_, binary);
  return Status::Ok();
}

Status OccupancyMap::SaveBt(const std::string& path) const {
  std::string binary;
  MBSLAM_RETURN_IF_ERROR(Serialize(&binary));
  return WriteStringAtomically(path, binary).WithContext("occupancy: writing " + path);
}

int64_t OccupancyMap::NumOccupied() const { return tree_ ? num_occupied_ : 0; }

std::optional<double> OccupancyMap::Occupancy(const Eigen::Vector3d& point_in_world) const {
  if (!tree_ || !point_in_world.allFinite()) {
    return std::nullopt;
  }
  octomap::OcTreeKey key;
  if (!KeyInTree(*tree_, ToOcto(point_in_world), key)) {
    return std::nullopt;
  }
  const octomap::OcTreeNode* node = tree_->search(key);
  if (!node) {
    return std::nullopt;
  }
  return node->getOccupancy();
}

bool OccupancyMap::IsOccupied(const Eigen::Vector3d& point_in_world) const {
  if (!tree_ || !point_in_world.allFinite()) {
    return false;
  }
  octomap::OcTreeKey key;
  if (!KeyInTree(*tree_, ToOcto(point_in_world), key)) {
    return false;
  }
  const octomap::OcTreeNode* node = tree_->search(key);
  return node != nullptr && tree_->isNodeOccupied(node);
}

std::vector<Eigen::Vector3d> OccupancyMap::OccupiedVoxelCenters() const {
  std::vector<Eigen::Vector3d> centers;
  if (!tree_) {
    return centers;
  }
  const double res = tree_->getResolution();
  const unsigned max_depth = tree_->getTreeDepth();
  for (auto it = tree_->begin_leafs(), end = tree_->end_leafs(); it != end; ++it) {
    if (!tree_->isNodeOccupied(*it)) {
      continue;
    }
    const octomap::point3d c = it.getCoordinate();
    const Eigen::Vector3d center(c.x(), c.y(), c.z());
    const int n = 1 << (max_depth - it.getDepth());  // voxels per edge of this leaf
    if (n == 1) {
      centers.push_back(center);
      continue;
    }
    const Eigen::Vector3d corner = center - Eigen::Vector3d::Constant(0.5 * n * res);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int k = 0; k < n; ++k) {
          centers.push_back(corner + res * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
        }
      }
    }
  }
  return centers;
}

}  // namespace mbslam
