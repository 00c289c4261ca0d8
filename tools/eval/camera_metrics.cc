#include "tools/eval/camera_metrics.h"

#include <algorithm>
#include <cmath>

#include "tools/eval/alignment.h"

namespace mbslam {
namespace eval {

const char* AlignmentName(Alignment a) {
  switch (a) {
    case Alignment::kNone:
      return "none";
    case Alignment::kSE3:
      return "se3";
    case Alignment::kSim3:
      return "sim3";
  }
  return "unknown";
}

bool ParseAlignment(const std::string& text, Alignment* a) {
  if (text == "none") {
    *a = Alignment::kNone;
  } else if (text == "se3") {
    *a = Alignment::kSE3;
  } else if (text == "sim3") {
    *a = Alignment::kSim3;
  } else {
    return false;
  }
  return true;
}

ErrorStats ErrorStats::From(std::vector<double> values) {
  ErrorStats s;
  s.count = static_cast<int>(values.size());
  if (values.empty()) {
    return s;
  }
  double sum = 0.0, sum_sq = 0.0;
  for (double v : values) {
    sum += v;
    sum_sq += v * v;
  }
  const double n = static_cast<double>(values.size());
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_sq / n);
  double var = 0.0;
  for (double v : values) {
    var += (v - s.mean) * (v - s.mean);
  }
  s.std = std::sqrt(var / n);
  std::sort(values.begin(), values.end());
  s.min = values.front();
  s.max = values.back();
  const size_t m = values.size() / 2;
  s.median = values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
  return s;
}

Status ComputeAte(const Trajectory& est, const Trajectory& gt, const AteOptions& options,
                  AteResult* result) {
  if (!options.Check()) {
    return Status::Error("ATE options: " + LastOptionError());
  }
  Alignment alignment = Alignment::kSim3;
  ParseAlignment(options.alignment, &alignment);
  *result = AteResult();
  result->num_est = static_cast<int>(est.size());
  result->num_gt = static_cast<int>(gt.size());
  result->pairs = AssociateByTime(est, gt, options.max_time_diff_us);
  if (result->pairs.empty()) {
    return Status::Error("ATE: no estimate pose within " +
                         std::to_string(options.max_time_diff_us) + " µs of a ground-truth pose");
  }
  std::vector<Eigen::Vector3d> src, dst;
  for (const auto& p : result->pairs) {
    src.push_back(est[p.est].pose.translation);
    dst.push_back(gt[p.gt].pose.translation);
  }
  if (options.fixed_gt_from_est) {
    result->gt_from_est = *options.fixed_gt_from_est;
  } else if (alignment != Alignment::kNone) {
    const bool with_scale = alignment == Alignment::kSim3;
    const Status st = UmeyamaAlignment(src, dst, with_scale, &result->gt_from_est);
    if (!st.ok()) {
      // A straight path leaves the rotation about it to the camera orientations.
      std::vector<Rigid3d> src_poses, dst_poses;
      for (const auto& p : result->pairs) {
        src_poses.push_back(est[p.est].pose);
        dst_poses.push_back(gt[p.gt].pose);
      }
      MBSLAM_RETURN_IF_ERROR(
          OrientationAlignment(src_poses, dst_poses, with_scale, &result->gt_from_est).WithContext("ATE"));
      result->orientation_aligned = true;
    }
  }
  std::vector<double> rot;
  for (const auto& p : result->pairs) {
    const Rigid3d aligned = result->gt_from_est * est[p.est].pose;
    result->est_aligned.push_back({est[p.est].utime, aligned});
    result->errors.push_back(TranslationDistance(aligned, gt[p.gt].pose));
    rot.push_back(RotationDistance(aligned, gt[p.gt].pose) * 180.0 / M_PI);
  }
  result->translation = ErrorStats::From(result->errors);
  result->rotation_deg = ErrorStats::From(rot);
  return Status::Ok();
}

Status ComputeRpe(const Trajectory& est, const Trajectory& gt,
                  const std::vector<AssociatedPair>& pairs, const RpeOptions& options,
                  RpeResult* result) {
  if (!options.Check()) {
    return Status::Error("RPE options: " + LastOptionError());
  }
  std::vector<double> trans, rot;
  for (size_t i = 0; i < pairs.size(); ++i) {
    size_t j = i + static_cast<size_t>(options.delta_frames);
    if (options.delta_us > 0) {
      const int64_t target = gt[pairs[i].gt].utime + options.delta_us;
      j = i + 1;
      while (j < pairs.size() && gt[pairs[j].gt].utime < target) {
        ++j;
      }
    }
    if (j >= pairs.size()) {
      break;
    }
    const Rigid3d gt_rel = gt[pairs[i].gt].pose.Inverse() * gt[pairs[j].gt].pose;
    Rigid3d est_rel = est[pairs[i].est].pose.Inverse() * est[pairs[j].est].pose;
    est_rel.translation *= options.est_scale;
    const Rigid3d e = gt_rel.Inverse() * est_rel;
    trans.push_back(e.translation.norm());
    rot.push_back(e.rotation.angularDistance(Eigen::Quaterniond::Identity()) * 180.0 / M_PI);
  }
  if (trans.empty()) {
    return Status::Error("RPE: fewer associated poses than the delta");
  }
  result->translation = ErrorStats::From(trans);
  result->rotation_deg = ErrorStats::From(rot);
  return Status::Ok();
}

double FractionTracked(const Trajectory& tracked_est, const Trajectory& gt,
                       int64_t max_time_diff_us) {
  if (gt.empty()) {
    return 0.0;
  }
  return static_cast<double>(AssociateByTime(tracked_est, gt, max_time_diff_us).size()) /
         static_cast<double>(gt.size());
}

}  // namespace eval
}  // namespace mbslam
