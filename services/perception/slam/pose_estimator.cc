#include "services/perception/slam/pose_estimator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "services/perception/segmentation/relative_motion.h"
#include "services/perception/slam/triangulation.h"

namespace mbslam {

namespace {

double HuberCost(double e, double h) { return e <= h ? 0.5 * e * e : h * (e - 0.5 * h); }

// Adds the Huber-weighted reprojection terms of the used correspondences (normalised
// units) to the normal equations H, g of a left perturbation of T; returns how many
// entered and adds their Huber cost to *cost when given.
int AddReprojectionTerms(const Rigid3d& T, const std::vector<Eigen::Vector3d>& X,
                         const std::vector<Eigen::Vector2d>& xy, const std::vector<uint8_t>& use, double huber,
                         Matrix6d* H, Vector6d* g, double* cost) {
  int n = 0;
  for (size_t i = 0; i < X.size(); ++i) {
    if (!use[i]) continue;
    Eigen::Vector2d proj;
    Eigen::Matrix<double, 2, 6> J;
    if (!ProjectionJacobians(T, X[i], &proj, &J, nullptr)) continue;
    const Eigen::Vector2d r = proj - xy[i];
    const double e = r.norm();
    const double w = e <= huber ? 1.0 : huber / e;
    *H += w * J.transpose() * J;
    *g += w * J.transpose() * r;
    if (cost) *cost += HuberCost(e, huber);
    ++n;
  }
  return n;
}

}  // namespace

Rigid3d RefinePose(const Rigid3d& initial, const std::vector<Eigen::Vector3d>& X,
                   const std::vector<Eigen::Vector2d>& xy, const std::vector<uint8_t>& use,
                   double focal, double huber_px, int iterations, Matrix6d* information,
                   const PoseRotationPrior* rotation_prior, double sigma_px) {
  Rigid3d T = initial;
  const double huber = huber_px / focal;
  const Eigen::Matrix3d prior_target_t =
      rotation_prior ? Eigen::Matrix3d(rotation_prior->cam_from_world.toRotationMatrix().transpose())
                     : Eigen::Matrix3d::Identity();
  const double prior_weight =
      rotation_prior ? std::pow(sigma_px / (focal * rotation_prior->sigma_rad), 2) : 0.0;
  Matrix6d H = Matrix6d::Zero();
  for (int iter = 0; iter < iterations; ++iter) {
    H.setZero();
    Vector6d g = Vector6d::Zero();
    const int n = AddReprojectionTerms(T, X, xy, use, huber, &H, &g, nullptr);
    if (n < 3) break;
    if (rotation_prior) {
      // r = Log(R target^T); under R' = Exp(w) R, dr/dw = J_l^-1(r).
      const Eigen::Vector3d r = LogSO3(T.RotationMatrix() * prior_target_t);
      const Eigen::Matrix3d Jr = LeftJacobianInverseSO3(r);
      H.block<3, 3>(3, 3) += prior_weight * Jr.transpose() * Jr;
      g.tail<3>() += prior_weight * Jr.transpose() * r;
    }
    const Vector6d delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) break;
    T = Rigid3d::Exp(delta) * T;
    if (delta.norm() < 1e-10) break;
  }
  if (information) *information = H;
  return T;
}

PoseEstimate EstimatePose(const std::vector<Eigen::Vector3d>& X, const std::vector<Eigen::Vector2d>& xy,
                          double focal, const std::optional<Rigid3d>& prior,
                          const PoseEstimatorOptions& o,
                          const std::optional<PoseRotationPrior>& rotation_prior) {
  const PoseRotationPrior* rp = rotation_prior ? &*rotation_prior : nullptr;
  PoseEstimate out;
  const size_t n = X.size();
  if (n < 6) return out;
  auto count_inliers = [&](const Rigid3d& T, double thresh_px, std::vector<uint8_t>* mask) {
    mask->assign(n, 0);
    int c = 0;
    for (size_t i = 0; i < n; ++i) {
      const double e = ReprojectionError(T, X[i], xy[i]) * focal;
      if (e <= thresh_px) {
        (*mask)[i] = 1;
        ++c;
      }
    }
    return c;
  };
  Rigid3d T;
  std::vector<uint8_t> mask;
  bool have = false;
  if (prior) {
    // Refine the prediction on all correspondences first (robust), then check it.
    std::vector<uint8_t> all(n, 1);
    const Rigid3d refined = RefinePose(*prior, X, xy, all, focal, o.huber_px, o.refine_iterations, nullptr, rp,
                                        o.sigma_px);
    const int c = count_inliers(refined, o.ransac_threshold_px, &mask);
    if (c >= o.prior_inlier_ratio * static_cast<double>(n)) {
      T = refined;
      have = true;
    }
  }
  if (!have) {
    std::vector<cv::Point3d> obj(n);
    std::vector<cv::Point2d> img(n);
    for (size_t i = 0; i < n; ++i) {
      obj[i] = cv::Point3d(X[i].x(), X[i].y(), X[i].z());
      img[i] = cv::Point2d(xy[i].x(), xy[i].y());
    }
    cv::Mat rvec, tvec;
    std::vector<int> inl;
    const bool ok = cv::solvePnPRansac(obj, img, cv::Mat::eye(3, 3, CV_64F), cv::Mat(), rvec, tvec, false,
                                       o.ransac_iterations, o.ransac_threshold_px / focal, 0.99, inl,
                                       cv::SOLVEPNP_EPNP);
    out.used_ransac = true;
    if (!ok || inl.size() < 6) return out;
    cv::Mat Rm;
    cv::Rodrigues(rvec, Rm);
    Eigen::Matrix3d R;
    Eigen::Vector3d t;
    cv::cv2eigen(Rm, R);
    cv::cv2eigen(tvec, t);
    T = Rigid3d(R, t);
    count_inliers(T, o.ransac_threshold_px, &mask);
  }
  Matrix6d info;
  for (int round = 0; round < 2; ++round) {
    T = RefinePose(T, X, xy, mask, focal, o.huber_px, o.refine_iterations, &info, rp, o.sigma_px);
    count_inliers(T, o.inlier_px, &mask);
  }
  int inliers = 0;
  double sq = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    ++inliers;
    const double e = ReprojectionError(T, X[i], xy[i]) * focal;
    sq += e * e;
  }
  out.cam_from_world = T;
  out.inliers = mask;
  out.num_inliers = inliers;
  out.rms_px = inliers ? std::sqrt(sq / inliers) : 0.0;
  // Covariance: sigma^2 (J^T J)^-1 with J in normalised units.
  const double sigma = o.sigma_px / focal;
  Eigen::FullPivLU<Matrix6d> lu(info);
  out.covariance = lu.isInvertible() ? Matrix6d(sigma * sigma * lu.inverse()) : Matrix6d(Matrix6d::Identity());
  out.ok = inliers >= 6;
  return out;
}

namespace {

// One Gauss-Newton refinement of EstimatePoseWithEpipolar's cost: Huber-weighted
// reprojection errors (use3) and epipolar distances (use2), all in normalised units, and
// the prior (|t| - length)^2 on the length of the motion since the length reference,
// weighted as a residual of standard deviation length_sigma against measurements of
// sigma0.
struct HybridProblem {
  const std::vector<Eigen::Vector3d>* X;
  const std::vector<Eigen::Vector2d>* xy;
  const EpipolarLinks* links;
  double huber = 0.0;
  int length_reference = 0;
  double length = 0.0;
  double length_weight = 0.0;  // (sigma0 / length_sigma)^2

  // Per reference: the motion since it, its rotation and essential matrix.
  struct Relative {
    Rigid3d rel;
    Eigen::Matrix3d R, E;
  };
  std::vector<Relative> Relatives(const Rigid3d& T) const {
    std::vector<Relative> out;
    for (const Rigid3d& ref : links->references) {
      Relative r;
      r.rel = T * ref.Inverse();
      r.R = r.rel.RotationMatrix();
      r.E = Hat(r.rel.translation) * r.R;
      out.push_back(r);
    }
    return out;
  }

  // Refines T; returns the robust cost at the result, and the information matrix.
  Rigid3d Refine(Rigid3d T, const std::vector<uint8_t>& use3, const std::vector<uint8_t>& use2, int iterations,
                 Matrix6d* information, double* cost) const {
    Matrix6d H = Matrix6d::Zero();
    for (int iter = 0; iter <= iterations; ++iter) {
      H.setZero();
      Vector6d g = Vector6d::Zero();
      double c = 0.0;
      int n = AddReprojectionTerms(T, *X, *xy, use3, huber, &H, &g, &c);
      // A left perturbation of T is the same left perturbation of T * ref^-1.
      const std::vector<Relative> rels = Relatives(T);
      for (size_t i = 0; i < links->xy_ref.size(); ++i) {
        if (!use2[i]) continue;
        const Relative& r = rels[static_cast<size_t>(links->reference[i])];
        Eigen::Matrix<double, 1, 6> J;
        const double d = EpipolarDistanceAndJacobian(r.R, r.E, links->xy_ref[i], links->xy_cur[i], &J);
        const double e = std::abs(d);
        const double w = e <= huber ? 1.0 : huber / e;
        H += w * J.transpose() * J;
        g += w * J.transpose() * d;
        c += HuberCost(e, huber);
        ++n;
      }
      // Under Exp([v; w]) the motion's translation t moves by v + w x t, its length by u . v.
      const Eigen::Vector3d& t = rels[static_cast<size_t>(length_reference)].rel.translation;
      const double len = t.norm();
      if (len > 1e-12 && length_weight > 0.0) {
        const Eigen::Vector3d u = t / len;
        const double r = len - length;
        H.topLeftCorner<3, 3>() += length_weight * u * u.transpose();
        g.head<3>() += length_weight * u * r;
        c += 0.5 * length_weight * r * r;
      }
      if (cost) *cost = c;
      if (iter == iterations || n < 6) break;
      const Vector6d delta = H.ldlt().solve(-g);
      if (!delta.allFinite()) break;
      T = Rigid3d::Exp(delta) * T;
      if (delta.norm() < 1e-10) iterations = iter + 1;  // one more pass: the cost and information at the result
    }
    if (information) *information = H;
    return T;
  }
};

}  // namespace

HybridPoseEstimate EstimatePoseWithEpipolar(const std::vector<Eigen::Vector3d>& X,
                                            const std::vector<Eigen::Vector2d>& xy, const EpipolarLinks& links,
                                            const Rigid3d& prior, int start_reference, int length_reference,
                                            double expected_length, double length_sigma_ratio, double focal,
                                            const PoseEstimatorOptions& o) {
  HybridPoseEstimate out;
  const size_t n3 = X.size(), n2 = links.xy_ref.size();
  const int num_refs = static_cast<int>(links.references.size());
  if (xy.size() != n3 || links.xy_cur.size() != n2 || links.reference.size() != n2 || n2 < 8 ||
      start_reference < 0 || start_reference >= num_refs || length_reference < 0 || length_reference >= num_refs) {
    return out;
  }
  for (int r : links.reference) {
    if (r < 0 || r >= num_refs) return out;
  }
  const double sigma0 = o.sigma_px / focal;
  const double length = std::max(0.0, expected_length);
  HybridProblem problem;
  problem.X = &X;
  problem.xy = &xy;
  problem.links = &links;
  problem.huber = o.huber_px / focal;
  problem.length_reference = length_reference;
  problem.length = length;
  const double length_sigma = length_sigma_ratio * length;
  problem.length_weight = length_sigma > 1e-12 ? (sigma0 * sigma0) / (length_sigma * length_sigma) : 0.0;

  // Starts: the prediction, unless it (nearly) stands still where a motion is expected
  // (the epipolar distances vanish with the translation), and the essential matrix of the
  // start reference's links with the expected length carried over to that reference.
  std::vector<Rigid3d> starts;
  if ((prior * links.references[static_cast<size_t>(length_reference)].Inverse()).translation.norm() >=
      0.1 * length) {
    starts.push_back(prior);
  }
  {
    std::vector<Eigen::Vector2d> a, b;
    for (size_t i = 0; i < n2; ++i) {
      if (links.reference[i] != start_reference) continue;
      a.push_back(links.xy_ref[i]);
      b.push_back(links.xy_cur[i]);
    }
    RelativeMotion motion;
    std::vector<uint8_t> inl;
    TwoViewOptions two_view;
    two_view.ransac_threshold_px = o.ransac_threshold_px;
    const Rigid3d& Ts = links.references[static_cast<size_t>(start_reference)];
    if (a.size() >= 8 && EstimateRelativeMotion(a, b, focal, two_view, &motion, &inl).ok()) {
      const Rigid3d predicted_rel = prior * Ts.Inverse();
      Eigen::Vector3d t = predicted_rel.translation;
      if (motion.translation_known) {
        // The length since the start reference, from the expected one since the length
        // reference and the prediction's ratio of the two.
        const double predicted_len = (prior * links.references[static_cast<size_t>(length_reference)].Inverse()).translation.norm();
        const double ratio = predicted_len > 1e-12 ? predicted_rel.translation.norm() / predicted_len : 1.0;
        t = motion.cam_n_from_cam_r.translation.normalized() * length * ratio;
      }
      starts.push_back(Rigid3d(motion.cam_n_from_cam_r.rotation, t) * Ts);
    }
  }
  if (starts.empty()) return out;
  const std::vector<uint8_t> all3(n3, 1), all2(n2, 1);
  Rigid3d T = prior;
  double best = std::numeric_limits<double>::infinity();
  for (const Rigid3d& start : starts) {
    double cost = 0.0;
    const Rigid3d refined = problem.Refine(start, all3, all2, o.refine_iterations, nullptr, &cost);
    if (refined.IsFinite() && cost < best) {
      best = cost;
      T = refined;
    }
  }
  // Inliers, and the refinement on them (twice, as EstimatePose).
  const double inlier = o.inlier_px / focal;
  std::vector<uint8_t> m3(n3, 0), m2(n2, 0);
  std::vector<double> link_distance(n2, 0.0);
  auto classify = [&](const Rigid3d& pose) {
    const std::vector<HybridProblem::Relative> rels = problem.Relatives(pose);
    for (size_t i = 0; i < n3; ++i) m3[i] = ReprojectionError(pose, X[i], xy[i]) <= inlier;
    for (size_t i = 0; i < n2; ++i) {
      const auto& r = rels[static_cast<size_t>(links.reference[i])];
      link_distance[i] = std::abs(EpipolarDistance(r.E, links.xy_ref[i], links.xy_cur[i]));
      m2[i] = link_distance[i] <= inlier;
    }
  };
  Matrix6d info = Matrix6d::Zero();
  classify(T);
  for (int round = 0; round < 2; ++round) {
    T = problem.Refine(T, m3, m2, o.refine_iterations, &info, nullptr);
    classify(T);
  }
  PoseEstimate& pose = out.pose;
  pose.cam_from_world = T;
  pose.inliers = m3;
  double sq = 0.0;
  for (size_t i = 0; i < n3; ++i) {
    if (!m3[i]) continue;
    ++pose.num_inliers;
    const double e = ReprojectionError(T, X[i], xy[i]) * focal;
    sq += e * e;
  }
  pose.rms_px = pose.num_inliers ? std::sqrt(sq / pose.num_inliers) : 0.0;
  sq = 0.0;
  for (size_t i = 0; i < n2; ++i) {
    if (!m2[i]) continue;
    ++out.num_link_inliers;
    sq += link_distance[i] * link_distance[i] * focal * focal;
  }
  out.link_inliers = m2;
  out.link_rms_px = out.num_link_inliers ? std::sqrt(sq / out.num_link_inliers) : 0.0;
  Eigen::FullPivLU<Matrix6d> lu(info);
  pose.covariance = lu.isInvertible() ? Matrix6d(sigma0 * sigma0 * lu.inverse()) : Matrix6d(Matrix6d::Identity());
  pose.ok = T.IsFinite() && out.num_link_inliers >= 8 && lu.isInvertible();
  return out;
}

GroundLengthEstimate GroundLengthOfMotion(const EpipolarLinks& links,
                                          const std::vector<uint8_t>& use,
                                          const Eigen::Vector4d& plane, const Rigid3d& length_ref,
                                          const Rigid3d& cam_from_world, double focal_px,
                                          double min_elevation_rad, double max_error_px,
                                          double length_step) {
  GroundLengthEstimate out;
  const size_t n_links = links.xy_ref.size();
  if (links.xy_cur.size() != n_links || links.reference.size() != n_links ||
      (!use.empty() && use.size() != n_links)) {
    return out;
  }
  for (int r : links.reference) {
    if (r < 0 || r >= static_cast<int>(links.references.size())) return out;
  }
  const Eigen::Vector3d n = plane.head<3>();
  if (!(std::abs(n.norm() - 1.0) < 1e-6) || !std::isfinite(plane[3]) || !(focal_px > 0.0))
    return out;
  const Eigen::Vector3d c0 = length_ref.Inverse().translation;
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  const Eigen::Vector3d motion = world_from_cam.translation - c0;
  if (!(motion.norm() > 1e-12)) return out;
  const Eigen::Vector3d u = motion.normalized();
  const double sin_min = std::sin(min_elevation_rad);
  // Each candidate: its ground point and its current ray (world); the length that
  // brings the point closest to the ray.
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector2d> xy_cur;
  std::vector<double> lengths;
  for (size_t i = 0; i < links.xy_ref.size(); ++i) {
    if (!use.empty() && !use[i]) continue;
    const Rigid3d world_from_ref = links.references[links.reference[i]].Inverse();
    const Eigen::Vector3d c = world_from_ref.translation;
    const Eigen::Vector3d a = world_from_ref.rotation * links.xy_ref[i].homogeneous();
    const double height = n.dot(c) + plane[3];
    const double nd = n.dot(a);
    if (!(height > 0.0) || !(-nd >= sin_min * a.norm()))
      continue;  // above the ground, ray below its horizon
    const Eigen::Vector3d X = c + (height / -nd) * a;
    const Eigen::Vector3d b = world_from_cam.rotation * links.xy_cur[i].homogeneous();
    // X - c0 = L u + m b in the least-squares sense.
    Eigen::Matrix<double, 3, 2> A;
    A << u, b;
    const Eigen::Matrix2d AtA = A.transpose() * A;
    if (std::abs(AtA.determinant()) < 1e-12 * AtA.trace() * AtA.trace())
      continue;  // ray along the motion
    const Eigen::Vector2d lm = AtA.ldlt().solve(A.transpose() * (X - c0));
    if (!(lm[1] > 0.0) || !(lm[0] > 0.0) || !std::isfinite(lm[0])) continue;
    points.push_back(X);
    xy_cur.push_back(links.xy_cur[i]);
    lengths.push_back(lm[0]);
  }
  out.candidates = static_cast<int>(points.size());
  if (points.empty()) return out;
  const Eigen::Matrix3d R = cam_from_world.RotationMatrix();
  const double max_error = max_error_px / focal_px;
  // At a length: the truncated sum of the points' reprojection errors (MSAC; smaller is
  // better) and how many project within max_error of their tracks.
  const auto agreement = [&](double L, int* count) {
    const Eigen::Vector3d centre = c0 + L * u;
    double cost = 0.0;
    *count = 0;
    for (size_t j = 0; j < points.size(); ++j) {
      const Eigen::Vector3d p = R * (points[j] - centre);
      double e = max_error;
      if (p.z() > 0.0) e = std::min(max_error, (p.head<2>() / p.z() - xy_cur[j]).norm());
      cost += e;
      *count += e < max_error;
    }
    return cost;
  };
  double best_cost = std::numeric_limits<double>::infinity();
  double best_length = 0.0;
  for (double L : lengths) {
    int count = 0;
    const double cost = agreement(L, &count);
    if (cost < best_cost) {
      best_cost = cost;
      best_length = L;
      out.support = count;
    }
  }
  // The truncated L1 cost is least at (about) a candidate: the length is the best one
  // (an average of the agreeing lengths would take in those of wall points near the ground).
  out.length = best_length;
  agreement((1.0 - length_step) * best_length, &out.support_shorter);
  agreement((1.0 + length_step) * best_length, &out.support_longer);
  out.ok = out.support > 0;
  return out;
}

}  // namespace mbslam
