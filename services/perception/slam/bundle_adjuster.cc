#include "services/perception/slam/bundle_adjuster.h"

#include <algorithm>
#include <set>

#include <ceres/ceres.h>

#include "services/perception/slam/cost_functions/reprojection_error.h"
#include "services/perception/slam/triangulation.h"

namespace mbslam {

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
  struct Block {
    double q[4];
    double t[3];
  };
  std::map<int64_t, Block> cams;
  for (const auto& [id, pose] : p->keyframes) {
    Block b;
    const Eigen::Quaterniond& q = pose.cam_from_world.rotation;
    b.q[0] = q.x();
    b.q[1] = q.y();
    b.q[2] = q.z();
    b.q[3] = q.w();
    for (int i = 0; i < 3; ++i) b.t[i] = pose.cam_from_world.translation[i];
    cams[id] = b;
  }
  std::map<int64_t, Eigen::Vector3d> pts = p->points;

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::LossFunction* loss = new ceres::HuberLoss(o.huber_px);  // owned by the problem
  auto* ordering = new ceres::ParameterBlockOrdering;
  for (const BaProblem::Obs& obs : p->observations) {
    Block& cam = cams.at(obs.keyframe_id);
    Eigen::Vector3d& X = pts.at(obs.point_id);
    problem.AddResidualBlock(CreateReprojectionError(obs.xy, p->focal_px), loss, cam.q, cam.t, X.data());
    ++summary.residuals;
  }
  for (auto& [id, X] : pts) ordering->AddElementToGroup(X.data(), 0);
  for (auto& [id, cam] : cams) {
    problem.SetManifold(cam.q, new ceres::EigenQuaternionManifold);
    ordering->AddElementToGroup(cam.q, 1);
    ordering->AddElementToGroup(cam.t, 1);
    if (p->keyframes.at(id).fixed) {
      problem.SetParameterBlockConstant(cam.q);
      problem.SetParameterBlockConstant(cam.t);
    }
  }
  if (p->use_odometry) {
    // Consecutive keyframes with odometry: metric displacement priors (scale).
    const BaProblem::Pose* prev = nullptr;
    Block* prev_block = nullptr;
    for (auto& [id, pose] : p->keyframes) {
      if (!pose.has_odometry) continue;
      if (prev != nullptr) {
        // Displacement of camera b relative to camera a, expressed in a's frame.
        const Eigen::Vector3d d = (prev->odom_from_cam.Inverse() * pose.odom_from_cam).translation;
        const double sigma = o.odometry_sigma_floor_m + o.odometry_sigma_per_m * d.norm();
        Block& cur = cams.at(id);
        problem.AddResidualBlock(CreateOdometryTranslationPrior(d, sigma), nullptr, prev_block->q,
                                 prev_block->t, cur.q, cur.t);
      }
      prev = &pose;
      prev_block = &cams.at(id);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::SPARSE_SCHUR;
  options.linear_solver_ordering.reset(ordering);
  options.max_num_iterations = o.max_iterations;
  options.max_solver_time_in_seconds = o.max_seconds;
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
    const Block& b = cams.at(id);
    pose.cam_from_world = Rigid3d(Eigen::Quaterniond(b.q[3], b.q[0], b.q[1], b.q[2]),
                                  Eigen::Vector3d(b.t[0], b.t[1], b.t[2]));
  }
  p->points = pts;
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
