#include "tools/eval/object_metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "tools/eval/hungarian.h"

namespace mbslam {
namespace eval {

bool PredictedVolume::Contains(const Eigen::Vector3d& point) const {
  const Eigen::Vector3d local = orientation.conjugate() * (point - center);
  return (local.cwiseAbs().array() <= half_extent.array()).all();
}

bool PredictedVolume::Overlaps(const Eigen::Vector3d& other_center,
                               const Eigen::Quaterniond& other_orientation,
                               const Eigen::Vector3d& other_half_extent) const {
  // Separating axis test of two oriented boxes: the 3 + 3 face normals and their 9 cross
  // products; the boxes are apart when their projections on one axis do not meet.
  const Eigen::Matrix3d A = orientation.toRotationMatrix();
  const Eigen::Matrix3d B = other_orientation.toRotationMatrix();
  const Eigen::Vector3d d = other_center - center;
  auto separated = [&](const Eigen::Vector3d& axis) {
    const double n = axis.norm();
    if (n < 1e-12) return false;  // parallel edges: covered by the face normals
    const Eigen::Vector3d u = axis / n;
    const double ra = (A.transpose() * u).cwiseAbs().dot(half_extent);
    const double rb = (B.transpose() * u).cwiseAbs().dot(other_half_extent);
    return std::abs(d.dot(u)) > ra + rb;
  };
  for (int i = 0; i < 3; ++i) {
    if (separated(A.col(i)) || separated(B.col(i))) return false;
  }
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      if (separated(A.col(i).cross(B.col(j)))) return false;
    }
  }
  return true;
}

bool InterpolatePose(const Trajectory& poses, int64_t utime, int64_t max_gap_us, Rigid3d* pose) {
  if (poses.empty()) {
    return false;
  }
  auto it = std::lower_bound(poses.begin(), poses.end(), utime,
                             [](const TimedPose& p, int64_t t) { return p.utime < t; });
  if (it != poses.end() && it->utime == utime) {
    *pose = it->pose;
    return true;
  }
  if (it == poses.begin() || it == poses.end()) {
    return false;
  }
  const TimedPose& b = *it;
  const TimedPose& a = *std::prev(it);
  if (b.utime - a.utime > max_gap_us) {
    return false;
  }
  *pose = Rigid3d::Interpolate(
      a.pose, b.pose,
      static_cast<double>(utime - a.utime) / static_cast<double>(b.utime - a.utime));
  return true;
}

namespace {

// The body's true pose at the time a volume predicts for, if the volume is at the scored
// horizon and the truth reaches that time.
bool TruePoseForVolume(const PredictedVolume& v, const BodyTruth& body,
                       const ObjectMetricsOptions& options, Rigid3d* pose) {
  if (std::llabs(v.horizon_us - options.horizon_us) > options.horizon_tolerance_us) return false;
  return InterpolatePose(body.poses, v.utime, 1000000, pose);
}

double Ratio(int num, int den) { return den > 0 ? static_cast<double>(num) / den : 0.0; }

double MedianOrNegative(std::vector<double> v) {
  if (v.empty()) return -1.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}

// Truth at the time of an estimate sample: nearest ground-truth sample within the
// tolerance (ground truth is per image, estimates are per image too).
bool TruthAt(const Trajectory& poses, int64_t utime, int64_t tolerance, Rigid3d* pose) {
  auto it = std::lower_bound(poses.begin(), poses.end(), utime,
                             [](const TimedPose& p, int64_t t) { return p.utime < t; });
  int64_t best = std::numeric_limits<int64_t>::max();
  for (auto jt : {it, it == poses.begin() ? poses.end() : std::prev(it)}) {
    if (jt == poses.end()) {
      continue;
    }
    const int64_t dt = std::llabs(jt->utime - utime);
    if (dt <= tolerance && dt < best) {
      best = dt;
      *pose = jt->pose;
    }
  }
  return best != std::numeric_limits<int64_t>::max();
}

struct Common {
  int64_t utime;
  Eigen::Vector3d est;     // estimate mapped into the truth world
  Eigen::Vector3d truth;   // body centre
  Eigen::Vector3d camera;  // camera centre
  Rigid3d cam_from_world;
  double est_depth;  // < 0 if not given (truth units)
  const ObjectSample* sample;
};

std::vector<Common> CommonSamples(const ObjectEstimate& est, const BodyTruth& body,
                                  const Trajectory& gt_camera, const Sim3d& gt_from_est,
                                  int64_t tolerance) {
  std::vector<Common> out;
  for (const auto& s : est.samples) {
    Rigid3d body_pose, cam_pose;
    if (!TruthAt(body.poses, s.utime, tolerance, &body_pose) ||
        !TruthAt(gt_camera, s.utime, tolerance, &cam_pose)) {
      continue;
    }
    Common c;
    c.utime = s.utime;
    c.est = gt_from_est * s.position;
    c.truth = body_pose.translation;
    c.camera = cam_pose.translation;
    c.cam_from_world = cam_pose.Inverse();
    c.est_depth = s.depth >= 0.0 ? s.depth * gt_from_est.scale : -1.0;
    c.sample = &s;
    out.push_back(c);
  }
  return out;
}

}  // namespace

Status EvaluateObjects(const std::map<int, ObjectEstimate>& estimates,
                       const std::map<int, BodyTruth>& truth, const Trajectory& gt_camera,
                       const Sim3d& gt_from_est, const ObjectMetricsOptions& options,
                       ObjectsEvaluation* result) {
  if (!options.Check()) {
    return Status::Error("object metrics options: " + LastOptionError());
  }
  *result = ObjectsEvaluation();
  result->num_est_objects = static_cast<int>(estimates.size());
  result->num_gt_bodies = static_cast<int>(truth.size());
  std::vector<const ObjectEstimate*> est_list;
  std::vector<const BodyTruth*> gt_list;
  for (const auto& e : estimates) {
    est_list.push_back(&e.second);
  }
  for (const auto& t : truth) {
    gt_list.push_back(&t.second);
  }
  // Association: mean distance over common samples, gated, Hungarian.
  const double kForbidden = 1e9;
  Eigen::MatrixXd cost =
      Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(est_list.size()),
                                static_cast<Eigen::Index>(gt_list.size()), kForbidden);
  for (size_t i = 0; i < est_list.size(); ++i) {
    for (size_t j = 0; j < gt_list.size(); ++j) {
      const auto common = CommonSamples(*est_list[i], *gt_list[j], gt_camera, gt_from_est,
                                        options.max_time_diff_us);
      if (static_cast<int>(common.size()) < options.min_samples) {
        continue;
      }
      double sum = 0.0;
      for (const auto& c : common) {
        sum += (c.est - c.truth).norm();
      }
      const double mean = sum / static_cast<double>(common.size());
      if (mean <= options.max_match_distance) {
        cost(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = mean;
      }
    }
  }
  const std::vector<int> assignment = SolveAssignment(cost);
  const Sim3d est_from_gt = gt_from_est.Inverse();
  std::vector<double> all_rel, all_ratios;
  for (size_t i = 0; i < est_list.size(); ++i) {
    const int j = assignment[i];
    const int n = static_cast<int>(est_list[i]->samples.size());
    result->est_samples += n;
    if (j < 0 || cost(static_cast<Eigen::Index>(i), j) >= kForbidden) {
      ++result->unmatched_est;
      result->unmatched_samples += n;
      if (cost.row(static_cast<Eigen::Index>(i)).minCoeff() < kForbidden) {
        ++result->unmatched_fragments;
        result->fragment_samples += n;
      } else if (n < options.min_samples) {
        ++result->unmatched_short;
      } else {
        ++result->unmatched_phantoms;
        result->phantom_samples += n;
      }
      continue;
    }
    const ObjectEstimate& est = *est_list[i];
    const BodyTruth& body = *gt_list[static_cast<size_t>(j)];
    const auto common = CommonSamples(est, body, gt_camera, gt_from_est, options.max_time_diff_us);
    ObjectResult r;
    r.est_id = est.id;
    r.gt_id = body.id;
    r.gt_name = body.name;
    r.num_samples = static_cast<int>(common.size());
    // Best scale about the camera: minimise sum |c + s (p - c) - g|^2.
    double num = 0.0, den = 0.0;
    for (const auto& c : common) {
      num += (c.est - c.camera).dot(c.truth - c.camera);
      den += (c.est - c.camera).squaredNorm();
    }
    r.best_scale = den > 0.0 ? num / den : 1.0;
    r.relative_scale_error = std::abs(r.best_scale - 1.0);
    std::vector<double> plain, scaled, depth;
    for (const auto& c : common) {
      plain.push_back((c.est - c.truth).norm());
      scaled.push_back((c.camera + r.best_scale * (c.est - c.camera) - c.truth).norm());
      const double true_depth = (c.cam_from_world * c.truth).z();
      const double est_depth = c.est_depth >= 0.0 ? c.est_depth : (c.cam_from_world * c.est).z();
      depth.push_back(std::abs(est_depth - true_depth));
      r.depth_error_over_time.emplace_back(c.utime, est_depth - true_depth);
    }
    if (!common.empty()) {
      const int64_t t0 = common.front().utime;
      std::vector<double> rel;
      for (const auto& c : common) {
        if (c.utime - t0 < options.settle_us) continue;
        const double range = (c.truth - c.camera).norm();
        if (!(range > 0.0)) continue;
        const double e = (c.est - c.truth).norm() / range;
        if (rel.empty()) r.rel_error_at_settle = e;
        rel.push_back(e);
        all_rel.push_back(e);
      }
      r.settled_samples = static_cast<int>(rel.size());
      if (!rel.empty()) {
        double sum = 0.0;
        for (double e : rel) sum += e;
        r.rel_error_settled_mean = sum / static_cast<double>(rel.size());
        std::vector<double> sorted = rel;
        std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
        r.rel_error_settled_median = sorted[sorted.size() / 2];
      }
    }
    r.position_error = ErrorStats::From(plain);
    r.position_error_scaled = ErrorStats::From(scaled);
    r.depth_error = ErrorStats::From(depth);
    // Predicted volumes at the horizon: does the true centre lie inside the box?
    std::vector<double> ratios;
    for (const auto& s : est.samples) {
      for (const auto& v : s.volumes) {
        Rigid3d body_pose;
        if (!TruePoseForVolume(v, body, options, &body_pose)) continue;
        ++r.volumes_checked;
        if (v.Contains(est_from_gt * body_pose.translation)) {
          ++r.volumes_hit;
        }
        const double true_volume = body.extent.x() * body.extent.y() * body.extent.z();
        if (true_volume > 0.0) {
          const Eigen::Vector3d size = 2.0 * gt_from_est.scale * v.half_extent;
          const double ratio = size.x() * size.y() * size.z() / true_volume;
          ratios.push_back(ratio);
          all_ratios.push_back(ratio);
        }
      }
    }
    r.hit_rate = Ratio(r.volumes_hit, r.volumes_checked);
    r.volume_ratio_median = MedianOrNegative(ratios);
    result->volumes_checked += r.volumes_checked;
    result->volumes_hit += r.volumes_hit;
    result->objects.push_back(r);
  }
  // Every estimate's volumes against the body nearest to its sample.
  for (const ObjectEstimate* est : est_list) {
    for (const auto& s : est->samples) {
      const Eigen::Vector3d p = gt_from_est * s.position;
      const BodyTruth* nearest = nullptr;
      double best = options.max_match_distance;
      for (const BodyTruth* body : gt_list) {
        Rigid3d pose;
        if (!InterpolatePose(body->poses, s.utime, 1000000, &pose)) continue;
        const double d = (pose.translation - p).norm();
        if (d <= best) {
          best = d;
          nearest = body;
        }
      }
      if (nearest == nullptr) continue;
      for (const auto& v : s.volumes) {
        Rigid3d body_pose;
        if (!TruePoseForVolume(v, *nearest, options, &body_pose)) continue;
        ++result->volumes_checked_all;
        if (v.Contains(est_from_gt * body_pose.translation)) ++result->volumes_hit_all;
        if (nearest->extent.allFinite() && (nearest->extent.array() > 0.0).all() &&
            v.Overlaps(est_from_gt * body_pose.translation, est_from_gt.rotation * body_pose.rotation,
                       0.5 * nearest->extent / gt_from_est.scale)) {
          ++result->volumes_overlapping_all;
        }
      }
    }
  }
  result->overlap_rate_all = Ratio(result->volumes_overlapping_all, result->volumes_checked_all);
  result->hit_rate_all = Ratio(result->volumes_hit_all, result->volumes_checked_all);
  result->settled_samples = static_cast<int>(all_rel.size());
  if (!all_rel.empty()) {
    double sum = 0.0;
    for (double e : all_rel) sum += e;
    result->rel_error_settled_mean = sum / static_cast<double>(all_rel.size());
  }
  result->volume_ratio_median = MedianOrNegative(all_ratios);
  result->hit_rate = Ratio(result->volumes_hit, result->volumes_checked);
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
