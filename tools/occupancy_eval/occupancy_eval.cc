#include "tools/occupancy_eval/occupancy_eval.h"

#include <octomap/OcTree.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/util/atomic_file.h"
#include "tools/eval/camera_metrics.h"

namespace mbslam {
namespace eval {
namespace {

// Largest number of samples per edge of an estimated voxel that is coarser than the
// scoring grid (count).
constexpr int kMaxSamplesPerEdge = 8;

// The true pose of frame k: cam_trajectory.tum has one pose per frame; fall back to the
// nearest pose in time (within 1 ms) when the two lists do not line up.
bool FramePose(const SequenceFolder& seq, size_t k, Rigid3d* world_from_cam) {
  const int64_t utime = seq.utimes[k];
  if (k < seq.camera.size() && seq.camera[k].utime == utime) {
    *world_from_cam = seq.camera[k].pose;
    return true;
  }
  auto it = std::lower_bound(seq.camera.begin(), seq.camera.end(), utime,
                             [](const TimedPose& p, int64_t t) { return p.utime < t; });
  const TimedPose* best = nullptr;
  if (it != seq.camera.end()) {
    best = &*it;
  }
  if (it != seq.camera.begin()) {
    const TimedPose* before = &*(it - 1);
    if (best == nullptr || utime - before->utime < best->utime - utime) {
      best = before;
    }
  }
  if (best == nullptr || std::llabs(best->utime - utime) > 1000) {
    return false;
  }
  *world_from_cam = best->pose;
  return true;
}

}  // namespace

bool OccupancyEvalOptions::Check() const {
  MBSLAM_CHECK_OPTION_GE(resolution_m, 0.0);
  MBSLAM_CHECK_OPTION_GT(max_range_m, 0.0);
  MBSLAM_CHECK_OPTION_GE(pixel_step, 1);
  MBSLAM_CHECK_OPTION_GE(frame_step, 1);
  Alignment a;
  MBSLAM_CHECK_OPTION(ParseAlignment(alignment, &a));
  MBSLAM_CHECK_OPTION_GE(max_time_diff_us, 0);
  return true;
}

bool VoxelGrid::KeyOf(const Eigen::Vector3d& point, int64_t ijk[3]) const {
  if (!point.allFinite()) {
    return false;
  }
  for (int a = 0; a < 3; ++a) {
    const double k = std::floor(point[a] / resolution_);
    if (!(std::fabs(k) < static_cast<double>(kOffset - 2))) {
      return false;
    }
    ijk[a] = static_cast<int64_t>(k);
  }
  return true;
}

uint64_t VoxelGrid::Pack(const int64_t ijk[3]) {
  return (static_cast<uint64_t>(ijk[0] + kOffset) << 42) |
         (static_cast<uint64_t>(ijk[1] + kOffset) << 21) | static_cast<uint64_t>(ijk[2] + kOffset);
}

bool VoxelGrid::Insert(const Eigen::Vector3d& point) {
  int64_t ijk[3];
  if (!KeyOf(point, ijk)) {
    return false;
  }
  keys_.insert(Pack(ijk));
  return true;
}

bool VoxelGrid::Contains(const Eigen::Vector3d& point) const {
  int64_t ijk[3];
  return KeyOf(point, ijk) && keys_.count(Pack(ijk)) > 0;
}

bool VoxelGrid::ContainsNear(const Eigen::Vector3d& point) const {
  int64_t ijk[3];
  if (!KeyOf(point, ijk)) {
    return false;
  }
  for (int64_t i = -1; i <= 1; ++i) {
    for (int64_t j = -1; j <= 1; ++j) {
      for (int64_t k = -1; k <= 1; ++k) {
        const int64_t n[3] = {ijk[0] + i, ijk[1] + j, ijk[2] + k};
        if (keys_.count(Pack(n)) > 0) {
          return true;
        }
      }
    }
  }
  return false;
}

std::vector<Eigen::Vector3d> VoxelGrid::Centers() const {
  std::vector<Eigen::Vector3d> centers;
  centers.reserve(keys_.size());
  const uint64_t mask = (uint64_t{1} << 21) - 1;
  for (const uint64_t key : keys_) {
    const int64_t i = static_cast<int64_t>((key >> 42) & mask) - kOffset;
    const int64_t j = static_cast<int64_t>((key >> 21) & mask) - kOffset;
    const int64_t k = static_cast<int64_t>(key & mask) - kOffset;
    centers.emplace_back((static_cast<double>(i) + 0.5) * resolution_,
                         (static_cast<double>(j) + 0.5) * resolution_,
                         (static_cast<double>(k) + 0.5) * resolution_);
  }
  return centers;
}

Status ParseOccupiedVoxels(const std::string& binary, OccupiedVoxels* voxels) {
  *voxels = OccupiedVoxels();
  octomap::OcTree tree(0.1);
  std::istringstream in(binary);
  if (!tree.readBinary(in)) {
    return Status::Error("not an OctoMap binary OcTree (OcTree::readBinary failed)");
  }
  voxels->resolution = tree.getResolution();
  const unsigned max_depth = tree.getTreeDepth();
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) {
      continue;
    }
    const octomap::point3d c = it.getCoordinate();
    const Eigen::Vector3d center(c.x(), c.y(), c.z());
    const int n = 1 << (max_depth - it.getDepth());
    const Eigen::Vector3d corner = center - Eigen::Vector3d::Constant(0.5 * n * voxels->resolution);
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        for (int k = 0; k < n; ++k) {
          voxels->centers.push_back(corner + voxels->resolution *
                                                 Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5));
        }
      }
    }
  }
  return Status::Ok();
}

Status ReadOccupiedVoxels(const std::string& bt_path, OccupiedVoxels* voxels) {
  std::string binary;
  MBSLAM_RETURN_IF_ERROR(ReadFileToString(bt_path, &binary));
  return ParseOccupiedVoxels(binary, voxels).WithContext(bt_path);
}

Status VoxelizeTrueSurface(const SequenceFolder& seq, double resolution_m,
                           const OccupancyEvalOptions& options, int64_t first_utime,
                           int64_t last_utime, TrueSurface* surface) {
  if (!(resolution_m > 0.0)) {
    return Status::Error("scoring resolution must be > 0");
  }
  surface->all = VoxelGrid(resolution_m);
  surface->observed = VoxelGrid(resolution_m);
  surface->frames_used = 0;
  surface->pixels_used = 0;
  const size_t n = seq.utimes.size();
  if (seq.depths.size() != n) {
    return Status::Error("the sequence has " + std::to_string(seq.depths.size()) +
                         " depth maps for " + std::to_string(n) +
                         " frames (generate it with depth output)");
  }
  const bool use_masks = !seq.masks.empty();
  if (use_masks && seq.masks.size() != n) {
    return Status::Error("the sequence has " + std::to_string(seq.masks.size()) + " masks for " +
                         std::to_string(n) + " frames");
  }
  if (seq.camera.empty()) {
    return Status::Error("the sequence has no cam_trajectory.tum");
  }
  const CameraIntrinsics& K = seq.intrinsics;
  const int step = options.pixel_step;
  // Normalised rays (x/z, y/z) of the sampled pixels, the same for every frame.
  std::vector<Eigen::Vector2d> rays;
  std::vector<Eigen::Vector2i> pixels;
  for (int v = 0; v < K.height; v += step) {
    for (int u = 0; u < K.width; u += step) {
      rays.push_back(K.PixelToNormalized(Eigen::Vector2d(u, v)));
      pixels.emplace_back(u, v);
    }
  }
  for (size_t k = 0; k < n; k += static_cast<size_t>(options.frame_step)) {
    if (seq.utimes[k] < first_utime || seq.utimes[k] > last_utime) {
      continue;
    }
    Rigid3d world_from_cam;
    if (!FramePose(seq, k, &world_from_cam)) {
      continue;
    }
    const cv::Mat depth = cv::imread(seq.depths[k], cv::IMREAD_UNCHANGED);
    if (depth.empty() || depth.channels() != 1 ||
        (depth.type() != CV_32F && depth.type() != CV_16U)) {
      return Status::Error(seq.depths[k] +
                           ": expected a one-channel float (m) or 16-bit (mm) depth map");
    }
    if (depth.cols != K.width || depth.rows != K.height) {
      return Status::Error(seq.depths[k] + ": size differs from the calibration");
    }
    cv::Mat mask;
    if (use_masks) {
      mask = cv::imread(seq.masks[k], cv::IMREAD_UNCHANGED);
      if (mask.empty() || mask.channels() != 1 || mask.size() != depth.size() ||
          (mask.type() != CV_16U && mask.type() != CV_8U)) {
        return Status::Error(seq.masks[k] + ": expected a one-channel mask of the image size");
      }
    }
    for (size_t i = 0; i < rays.size(); ++i) {
      const int u = pixels[i].x(), v = pixels[i].y();
      if (use_masks) {
        const int body = mask.type() == CV_16U ? mask.at<uint16_t>(v, u) : mask.at<uint8_t>(v, u);
        if (body != 0) {
          continue;  // a moving body, not the static world
        }
      }
      const double z = depth.type() == CV_32F ? static_cast<double>(depth.at<float>(v, u))
                                              : 0.001 * depth.at<uint16_t>(v, u);
      if (!(z > 0.0) || !std::isfinite(z)) {
        continue;  // no surface (sky)
      }
      const Eigen::Vector3d point_in_cam(rays[i].x() * z, rays[i].y() * z, z);
      const Eigen::Vector3d point_in_world = world_from_cam * point_in_cam;
      surface->all.Insert(point_in_world);
      if (point_in_cam.norm() <= options.max_range_m) {
        surface->observed.Insert(point_in_world);
      }
      ++surface->pixels_used;
    }
    ++surface->frames_used;
  }
  return Status::Ok();
}

OccupancyScore ScoreOccupancy(const std::vector<Eigen::Vector3d>& est_centers_in_gt,
                              double est_voxel_m, const Eigen::Quaterniond& est_rotation,
                              const TrueSurface& truth) {
  OccupancyScore score;
  const double res = truth.all.resolution();
  VoxelGrid est(res);
  const int samples =
      std::clamp(static_cast<int>(std::ceil(est_voxel_m / res - 1e-9)), 1, kMaxSamplesPerEdge);
  std::vector<Eigen::Vector3d> offsets;
  for (int i = 0; i < samples; ++i) {
    for (int j = 0; j < samples; ++j) {
      for (int k = 0; k < samples; ++k) {
        const Eigen::Vector3d local =
            est_voxel_m *
            (Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5) / samples - Eigen::Vector3d::Constant(0.5));
        offsets.push_back(est_rotation * local);
      }
    }
  }
  for (const Eigen::Vector3d& c : est_centers_in_gt) {
    for (const Eigen::Vector3d& o : offsets) {
      est.Insert(c + o);
    }
  }
  for (const Eigen::Vector3d& c : est.Centers()) {
    ++score.voxels_est;
    if (truth.all.ContainsNear(c)) {
      ++score.voxels_est_near;
    }
  }
  for (const Eigen::Vector3d& c : truth.observed.Centers()) {
    ++score.voxels_true;
    if (est.ContainsNear(c)) {
      ++score.voxels_true_found;
    }
  }
  score.voxels_true_all = static_cast<int64_t>(truth.all.size());
  score.precision = score.voxels_est > 0 ? static_cast<double>(score.voxels_est_near) /
                                               static_cast<double>(score.voxels_est)
                                         : 0.0;
  score.recall = score.voxels_true > 0 ? static_cast<double>(score.voxels_true_found) /
                                             static_cast<double>(score.voxels_true)
                                       : 0.0;
  return score;
}

Status EvaluateOccupancy(const std::string& bt_path, const Trajectory& est_trajectory,
                         const std::string& sequence_dir, const OccupancyEvalOptions& options,
                         OccupancyEvalResult* result) {
  *result = OccupancyEvalResult();
  if (!options.Check()) {
    return Status::Error("occupancy eval options: " + LastOptionError());
  }
  SequenceFolder seq;
  MBSLAM_RETURN_IF_ERROR(ReadSequenceFolder(sequence_dir, &seq));
  OccupiedVoxels voxels;
  MBSLAM_RETURN_IF_ERROR(ReadOccupiedVoxels(bt_path, &voxels));
  result->est_resolution = voxels.resolution;

  Alignment alignment = Alignment::kSim3;
  ParseAlignment(options.alignment, &alignment);
  if (alignment != Alignment::kNone) {
    if (est_trajectory.empty()) {
      return Status::Error("alignment '" + options.alignment +
                           "' needs the estimated camera trajectory");
    }
    AteOptions ate_options;
    ate_options.alignment = options.alignment;
    ate_options.max_time_diff_us = options.max_time_diff_us;
    AteResult ate;
    MBSLAM_RETURN_IF_ERROR(ComputeAte(est_trajectory, seq.camera, ate_options, &ate));
    result->gt_from_est = ate.gt_from_est;
    result->aligned_poses = static_cast<int>(ate.pairs.size());
    result->ate_rmse_m = ate.translation.rmse;
  }
  result->est_resolution_m = voxels.resolution * result->gt_from_est.scale;
  result->resolution_m =
      options.resolution_m > 0.0 ? options.resolution_m : result->est_resolution_m;

  int64_t first = INT64_MIN, last = INT64_MAX;
  if (!options.all_frames && !est_trajectory.empty()) {
    first = est_trajectory.front().utime - options.max_time_diff_us;
    last = est_trajectory.back().utime + options.max_time_diff_us;
  }
  TrueSurface truth;
  MBSLAM_RETURN_IF_ERROR(
      VoxelizeTrueSurface(seq, result->resolution_m, options, first, last, &truth));
  result->frames_used = truth.frames_used;
  if (truth.frames_used == 0) {
    return Status::Error(
        "no depth map of the sequence falls in the estimated trajectory's time span");
  }
  std::vector<Eigen::Vector3d> est_in_gt;
  est_in_gt.reserve(voxels.centers.size());
  for (const Eigen::Vector3d& c : voxels.centers) {
    est_in_gt.push_back(result->gt_from_est * c);
  }
  result->score =
      ScoreOccupancy(est_in_gt, result->est_resolution_m, result->gt_from_est.rotation, truth);
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
