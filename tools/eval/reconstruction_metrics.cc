#include "tools/eval/reconstruction_metrics.h"

#include <dirent.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

#include "common/util/statistics.h"
#include "tools/eval/alignment.h"
#include "tools/eval/point_metrics.h"

namespace mbslam {
namespace eval {
namespace {

double Rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
}

}  // namespace

double BoxSignedDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& extent) {
  const Eigen::Vector3d q = p.cwiseAbs() - 0.5 * extent;
  const double outside = q.cwiseMax(0.0).norm();
  return outside > 0.0 ? outside : q.maxCoeff();
}

double BoxSurfaceDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& extent) {
  return std::abs(BoxSignedDistance(p, extent));
}

Eigen::Vector3d FitTranslationToBoxSurface(const Eigen::Vector3d& extent, std::vector<Eigen::Vector3d>* points) {
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  if (points->size() < kMinShiftedPoints) return shift;
  const auto cost_of = [&](const Eigen::Vector3d& v) {
    double c = 0.0;
    for (const Eigen::Vector3d& p : *points) c += std::pow(BoxSignedDistance(p + v, extent), 2);
    return c;
  };
  double cost = cost_of(shift);
  double lambda = 1e-3;
  const double h = 1e-6 * std::max(1.0, extent.maxCoeff());
  for (int iter = 0; iter < 100; ++iter) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
    Eigen::Vector3d g = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& p0 : *points) {
      const Eigen::Vector3d p = p0 + shift;
      Eigen::Vector3d grad;  // of the signed distance, by central differences
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d dp = Eigen::Vector3d::Zero();
        dp[k] = h;
        grad[k] = (BoxSignedDistance(p + dp, extent) - BoxSignedDistance(p - dp, extent)) / (2.0 * h);
      }
      H += grad * grad.transpose();
      g += grad * BoxSignedDistance(p, extent);
    }
    bool improved = false;
    while (lambda < 1e8) {
      Eigen::Matrix3d A = H;
      A.diagonal() += lambda * (H.diagonal().array() + 1e-9).matrix();
      const Eigen::Vector3d delta = -A.ldlt().solve(g);
      if (!delta.allFinite()) break;
      const double trial_cost = cost_of(shift + delta);
      if (trial_cost < cost) {
        shift += delta;
        improved = cost - trial_cost > 1e-12 * std::max(cost, 1e-12);
        cost = trial_cost;
        lambda = std::max(1e-6, lambda * 0.3);
        break;
      }
      lambda *= 10.0;
    }
    if (!improved) break;
  }
  for (Eigen::Vector3d& p : *points) p += shift;
  return shift;
}

Status EvaluateReconstruction(const ReconstructionEstimate& est, const std::map<int, BodyTruth>& truth,
                              const Trajectory& gt_world_from_cam, int64_t max_time_diff_us, int min_samples,
                              ReconstructionResult* result) {
  bool found = false;
  double best = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d> best_points;  // the best body's frame
  Eigen::Vector3d best_shift = Eigen::Vector3d::Zero();
  for (const auto& [id, body] : truth) {
    std::vector<Rigid3d> src, dst;
    for (const TimedPose& e : est.obj_from_cam) {
      Rigid3d world_from_cam, world_from_body;
      if (!InterpolatePose(gt_world_from_cam, e.utime, max_time_diff_us, &world_from_cam)) continue;
      if (!InterpolatePose(body.poses, e.utime, max_time_diff_us, &world_from_body)) continue;
      src.push_back(e.pose);
      dst.push_back(world_from_body.Inverse() * world_from_cam);
    }
    if (static_cast<int>(src.size()) < min_samples) continue;
    Sim3d body_from_map;
    if (!OrientationAlignment(src, dst, /*with_scale=*/true, &body_from_map).ok()) continue;
    std::vector<double> err;
    double path = 0.0, range = 0.0;
    for (size_t i = 0; i < src.size(); ++i) {
      err.push_back((body_from_map * src[i].translation - dst[i].translation).norm());
      range += dst[i].translation.norm();
      if (i > 0) path += (dst[i].translation - dst[i - 1].translation).norm();
    }
    range /= static_cast<double>(src.size());
    const double rmse = Rms(err);
    if (!(range > 0.0) || rmse / range >= best) continue;
    best = rmse / range;
    found = true;
    ReconstructionResult& r = *result;
    r = ReconstructionResult();
    r.object_id = est.object_id;
    r.map_id = est.map_id;
    r.gt_id = id;
    r.gt_name = body.name;
    r.samples = static_cast<int>(src.size());
    r.scale = body_from_map.scale;
    r.path_length_m = path;
    r.mean_range_m = range;
    r.trajectory_rmse_m = rmse;
    r.trajectory_err_rel_path = path > 0.0 ? rmse / path : std::numeric_limits<double>::infinity();
    r.trajectory_err_rel_range = rmse / range;
    r.size_m = body.extent.maxCoeff();
    std::vector<double> d;
    int within = 0;
    best_points.clear();
    for (const Eigen::Vector3d& p : est.points) {
      best_points.push_back(body_from_map * p);
      d.push_back(BoxSurfaceDistance(best_points.back(), body.extent));
      within += d.back() <= 0.02 * r.size_m;
    }
    r.num_points = static_cast<int>(d.size());
    r.shape_rmse_m = Rms(d);
    r.shape_median_m = Median(d);
    if (r.size_m > 0.0) {
      r.shape_err_rel = r.shape_rmse_m / r.size_m;
      r.shape_err_rel_median = r.shape_median_m / r.size_m;
    }
    r.share_within_2pct = d.empty() ? 0.0 : static_cast<double>(within) / static_cast<double>(d.size());
    std::vector<Eigen::Vector3d> shifted = best_points;
    const Eigen::Vector3d shift = FitTranslationToBoxSurface(body.extent, &shifted);
    r.shape_translated = shifted.size() >= kMinShiftedPoints;
    std::vector<double> d_shifted;
    for (const Eigen::Vector3d& q : shifted) d_shifted.push_back(BoxSurfaceDistance(q, body.extent));
    r.shape_translated_rmse_m = Rms(d_shifted);
    if (r.size_m > 0.0) {
      r.shape_translated_err_rel = r.shape_translated_rmse_m / r.size_m;
      r.shape_translated_err_rel_median = Median(d_shifted) / r.size_m;
    }
    r.translation_fit_m = shift.norm();
    best_shift = shift;
  }
  if (found && std::getenv("EVAL_DUMP_SHAPE")) {
    // Each scored point in the body's frame with its distance to the body's surface.
    for (const Eigen::Vector3d& q : best_points) {
      std::fprintf(stderr, "SHAPE object %d map %lld body %d point %.3f %.3f %.3f distance %.3f (%.3f shifted)\n",
                   result->object_id, static_cast<long long>(result->map_id), result->gt_id, q.x(), q.y(), q.z(),
                   BoxSurfaceDistance(q, truth.at(result->gt_id).extent),
                   BoxSurfaceDistance(q + best_shift, truth.at(result->gt_id).extent));
    }
  }
  if (!found) return Status::Error("reconstruction of object " + std::to_string(est.object_id) + " map " +
                                   std::to_string(est.map_id) + ": no body with enough common samples");
  return Status::Ok();
}

Status ReadReconstructions(const std::string& dir, std::vector<ReconstructionEstimate>* out) {
  out->clear();
  DIR* d = ::opendir(dir.c_str());
  if (!d) return Status::Error("cannot open " + dir);
  std::vector<std::string> names;
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".tum") == 0) names.push_back(name.substr(0, name.size() - 4));
  }
  ::closedir(d);
  std::sort(names.begin(), names.end());
  for (const std::string& base : names) {
    ReconstructionEstimate r;
    const size_t us = base.find('_');
    if (us == std::string::npos) return Status::Error("reconstruction file name not <object>_<map>: " + base);
    try {
      r.object_id = std::stoi(base.substr(0, us));
      r.map_id = std::stoll(base.substr(us + 1));
    } catch (...) {
      return Status::Error("reconstruction file name not <object>_<map>: " + base);
    }
    MBSLAM_RETURN_IF_ERROR(ReadTumTrajectory(dir + "/" + base + ".tum", &r.obj_from_cam));
    MBSLAM_RETURN_IF_ERROR(ReadPointsFile(dir + "/" + base + ".xyz", &r.points));
    out->push_back(std::move(r));
  }
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
