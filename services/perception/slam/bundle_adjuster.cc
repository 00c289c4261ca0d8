#include "services/perception/slam/bundle_adjuster.h"

#include <algorithm>
#include <cstdlib>
#include <set>

#include <ceres/ceres.h>

#include "services/perception/slam/cost_functions/reprojection_error.h"
#include "services/perception/slam/triangulation.h"

namespace mbslam {

double RotationPriorSigma(double floor_rad, double rad_per_s, int64_t dt_us) {
  return floor_rad + rad_per_s * 1e-6 * static_cast<double>(std::abs(dt_us));
}

BaProblem ExtractBaProblem(const Map& map, int window, bool global, double focal_px, bool use_odometry) {
  BaProblem p;
  p.focal_px = focal_px;
  p.use_odometry = use_odometry;
  std::set<int64_t> window_ids;
  int count = 0;
  for (auto it = map.keyframes().rbegin(); it != map.keyframes().rend(); ++it) {
    if (!global && count >= window) break;
    window_ids.insert(it->first);
    ++count;
  }
  for (int64_t id : window_ids) {
    const Keyframe& k = *map.keyframe(id);
    for (int64_t pid : k.point_ids) {
      if (const MapPoint* mp = map.point(pid)) p.points[pid] = mp->position;
    }
  }
  for (const auto& [pid, pos] : p.points) {
    const MapPoint& mp = *map.point(pid);
    for (const Observation& o : mp.observations) {
      const Keyframe* k = map.keyframe(o.keyframe_id);
      if (!k) continue;
      if (!p.keyframes.count(o.keyframe_id)) {
        BaProblem::Pose pose;
        pose.cam_from_world = k->cam_from_world;
        pose.fixed = k->fixed || !window_ids.count(o.keyframe_id);
        pose.has_odometry = k->has_odometry;
        pose.odom_from_cam = k->odom_from_cam;
        pose.utime = k->utime;
        pose.rotation_prior = k->rotation_prior;
        p.keyframes[o.keyframe_id] = pose;
      }
      p.observations.push_back(BaProblem::Obs{o.keyframe_id, pid, o.xy});
    }
  }
  // Without any fixed keyframe the gauge is free: fix the oldest one.
  bool any_fixed = false;
  for (const auto& [id, pose] : p.keyframes) any_fixed |= pose.fixed;
  if (!any_fixed && !p.keyframes.empty()) p.keyframes.begin()->second.fixed = true;
  return p;
}

BaSummary SolveBa(BaProblem* p, const BundleAdjustmentOptions& o) {
  BaSummary summary;
  if (p->observations.empty()) return summary;
  // All parameters live in one array, points first, then cameras, in id order: Ceres
  // keeps its ordering groups as sets of pointers, so their order (and the floating
  // point summation order of the solve) must not depend on where the heap put them,
  // or lockstep replays would differ run to run.
  std::map<int64_t, size_t> point_index, cam_index;
  for (const auto& [id, X] : p->points) point_index.emplace(id, point_index.size());
  for (const auto& [id, pose] : p->keyframes) cam_index.emplace(id, cam_index.size());
  const size_t cam_offset = 3 * point_index.size();
  std::vector<double> params(cam_offset + 7 * cam_index.size());
  auto point_ptr = [&](int64_t id) { return params.data() + 3 * point_index.at(id); };
  auto q_ptr = [&](int64_t id) { return params.data() + cam_offset + 7 * cam_index.at(id); };
  auto t_ptr = [&](int64_t id) { return q_ptr(id) + 4; };
  for (const auto& [id, X] : p->points) {
    double* x = point_ptr(id);
    x[0] = X.x();
    x[1] = X.y();
    x[2] = X.z();
  }
  for (const auto& [id, pose] : p->keyframes) {
    const Eigen::Quaterniond& q = pose.cam_from_world.rotation;
    double* qp = q_ptr(id);
    qp[0] = q.x();
    qp[1] = q.y();
    qp[2] = q.z();
    qp[3] = q.w();
    double* tp = t_ptr(id);
    for (int i = 0; i < 3; ++i) tp[i] = pose.cam_from_world.translation[i];
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::LossFunction* loss = new ceres::HuberLoss(o.huber_px);  // owned by the problem
  auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
  for (const BaProblem::Obs& obs : p->observations) {
    problem.AddResidualBlock(CreateReprojectionError(obs.xy, p->focal_px), loss, q_ptr(obs.keyframe_id),
                             t_ptr(obs.keyframe_id), point_ptr(obs.point_id));
    ++summary.residuals;
  }
  for (const auto& [id, X] : p->points) ordering->AddElementToGroup(point_ptr(id), 0);
  for (const auto& [id, pose] : p->keyframes) {
    problem.SetManifold(q_ptr(id), new ceres::EigenQuaternionManifold);
    ordering->AddElementToGroup(q_ptr(id), 1);
    ordering->AddElementToGroup(t_ptr(id), 1);
    if (pose.fixed) {
      problem.SetParameterBlockConstant(q_ptr(id));
      problem.SetParameterBlockConstant(t_ptr(id));
    }
  }
  if (p->use_odometry) {
    // Consecutive keyframes with odometry: metric displacement priors (scale).
    const BaProblem::Pose* prev = nullptr;
    int64_t prev_id = -1;
    for (const auto& [id, pose] : p->keyframes) {
      if (!pose.has_odometry) continue;
      if (prev != nullptr) {
        // Displacement of camera b relative to camera a, expressed in a's frame.
        const Eigen::Vector3d d = (prev->odom_from_cam.Inverse() * pose.odom_from_cam).translation;
        const double sigma = o.odometry_sigma_floor_m + o.odometry_sigma_per_m * d.norm();
        problem.AddResidualBlock(CreateOdometryTranslationPrior(d, sigma), nullptr, q_ptr(prev_id),
                                 t_ptr(prev_id), q_ptr(id), t_ptr(id));
      }
      prev = &pose;
      prev_id = id;
    }
  }
  if (p->rotation_prior_floor_rad > 0.0 || p->rotation_prior_rad_per_s > 0.0) {
    // Consecutive keyframes (in id order) with rotation priors of the same reference.
    const BaProblem::Pose* prev = nullptr;
    int64_t prev_id = -1;
    for (const auto& [id, pose] : p->keyframes) {
      if (!pose.rotation_prior) continue;
      if (prev != nullptr && prev->rotation_prior->ref_id == pose.rotation_prior->ref_id &&
          !(prev->fixed && pose.fixed)) {
        const Eigen::Quaterniond b_from_a =
            pose.rotation_prior->cam_from_ref * prev->rotation_prior->cam_from_ref.conjugate();
        const double sigma =
            RotationPriorSigma(p->rotation_prior_floor_rad, p->rotation_prior_rad_per_s, pose.utime - prev->utime);
        problem.AddResidualBlock(CreateRelativeRotationPrior(b_from_a, sigma), nullptr, q_ptr(prev_id),
                                 q_ptr(id));
      }
      prev = &pose;
      prev_id = id;
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.linear_solver_ordering = ordering;
  options.max_num_iterations = o.max_iterations;
  if (o.time_limited) options.max_solver_time_in_seconds = o.max_seconds;
  options.num_threads = 1;
  options.minimizer_progress_to_stdout = false;
  options.logging_type = ceres::SILENT;
  ceres::Solver::Summary s;
  ceres::Solve(options, &problem, &s);
  summary.usable = s.IsSolutionUsable() && s.final_cost <= s.initial_cost;
  summary.iterations = static_cast<int>(s.iterations.size());
  summary.initial_cost = s.initial_cost;
  summary.final_cost = s.final_cost;
  summary.seconds = s.total_time_in_seconds;
  if (!summary.usable) return summary;
  for (auto& [id, pose] : p->keyframes) {
    const double* q = q_ptr(id);
    const double* t = t_ptr(id);
    pose.cam_from_world = Rigid3d(Eigen::Quaterniond(q[3], q[0], q[1], q[2]), Eigen::Vector3d(t[0], t[1], t[2]));
  }
  for (auto& [id, X] : p->points) {
    const double* x = point_ptr(id);
    X = Eigen::Vector3d(x[0], x[1], x[2]);
  }
  return summary;
}

int ApplyBaResult(const BaProblem& p, const BundleAdjustmentOptions& o, Map* map) {
  for (const auto& [id, pose] : p.keyframes) {
    if (pose.fixed) continue;
    if (Keyframe* k = map->keyframe(id)) k->cam_from_world = pose.cam_from_world;
  }
  for (const auto& [id, X] : p.points) {
    if (MapPoint* mp = map->point(id)) mp->position = X;
  }
  // Remove observations that are still outliers; points left with fewer than two go.
  int removed = 0;
  const double thresh = o.outlier_px / p.focal_px;
  std::vector<int64_t> dead;
  for (const auto& [id, X] : p.points) {
    MapPoint* mp = map->point(id);
    if (!mp) continue;
    std::vector<Observation> kept;
    for (const Observation& ob : mp->observations) {
      const Keyframe* k = map->keyframe(ob.keyframe_id);
      if (k && ReprojectionError(k->cam_from_world, mp->position, ob.xy) <= thresh) {
        kept.push_back(ob);
      } else {
        ++removed;
        if (Keyframe* km = map->keyframe(ob.keyframe_id)) {
          km->point_ids.erase(std::remove(km->point_ids.begin(), km->point_ids.end(), id), km->point_ids.end());
        }
      }
    }
    mp->observations = kept;
    if (mp->observations.size() < 2) dead.push_back(id);
  }
  for (int64_t id : dead) map->RemovePoint(id);
  return removed;
}

}  // namespace mbslam
