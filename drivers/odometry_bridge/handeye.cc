#include "drivers/odometry_bridge/handeye.h"

#include <Eigen/Dense>
#include <cmath>
#include <sstream>

#include "common/util/time.h"
#include "services/perception/geometry/pose_buffer.h"

namespace mbslam {
namespace {

constexpr double kDegToRad = M_PI / 180.0;

double Rms(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double sum = 0.0;
  for (double x : v) sum += x * x;
  return std::sqrt(sum / static_cast<double>(v.size()));
}

// Orthonormal basis whose third column is n.
Eigen::Matrix3d BasisWithThirdAxis(const Eigen::Vector3d& n) {
  const Eigen::Vector3d z = n.normalized();
  const Eigen::Vector3d helper =
      std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = (helper - helper.dot(z) * z).normalized();
  Eigen::Matrix3d p;
  p.col(0) = x;
  p.col(1) = z.cross(x);
  p.col(2) = z;
  return p;
}

}  // namespace

bool HandEyeOptions::Check() const {
  return (mode == "auto" || mode == "general" || mode == "planar") && planar_tolerance_deg > 0 &&
         min_rotation_deg >= 0 && std::isfinite(prior_offset_along_axis_m);
}

Status SolveHandEye(const std::vector<MotionPair>& pairs, const HandEyeOptions& options,
                    HandEyeResult* result) {
  if (!options.Check()) return Status::Error("hand-eye: bad options");
  if (pairs.size() < 2) return Status::Error("hand-eye: need at least 2 motion pairs, got " + std::to_string(pairs.size()));
  HandEyeResult r;
  r.pairs = static_cast<int>(pairs.size());

  // Rotation vectors of the turning pairs, signs aligned to a common direction.
  std::vector<Eigen::Vector3d> a, b;
  for (const MotionPair& p : pairs) {
    const Eigen::Vector3d av = LogSO3(p.base_motion.RotationMatrix());
    const Eigen::Vector3d bv = LogSO3(p.cam_motion.RotationMatrix());
    if (av.norm() < options.min_rotation_deg * kDegToRad) continue;
    a.push_back(av);
    b.push_back(bv);
  }
  r.rotating_pairs = static_cast<int>(a.size());
  if (a.empty()) {
    return Status::Error("hand-eye: the base never turned by " + std::to_string(options.min_rotation_deg) +
                         " deg or more; the rotation cannot be determined (drive turns)");
  }
  // Dominant turn axis (principal direction of the rotation vectors) and the spread.
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& v : a) scatter += v.normalized() * v.normalized().transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter);
  Eigen::Vector3d n = eig.eigenvectors().col(2);
  double max_dev = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].dot(n) < 0) {
      a[i] = -a[i];
      b[i] = -b[i];
    }
    max_dev = std::max(max_dev, std::acos(std::min(1.0, a[i].normalized().dot(n))));
  }
  const bool planar = options.mode == "planar" ||
                      (options.mode == "auto" && max_dev < options.planar_tolerance_deg * kDegToRad);
  r.planar = planar;

  Eigen::Matrix3d rx;
  Eigen::Vector3d tx;
  double scale = 1.0;
  if (!planar) {
    if (max_dev < 0.5 * kDegToRad) {
      return Status::Error("hand-eye: every turn is about the same axis; use the planar mode "
                           "(the camera offset along that axis is then unobservable)");
    }
    // Procrustes: min sum |a_i - R b_i|^2.
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (size_t i = 0; i < a.size(); ++i) h += b[i] * a[i].transpose();
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
    rx = svd.matrixV() * d * svd.matrixU().transpose();
    // Translation and scale: (R_A - I) t_X - s R_X t_B = -t_A.
    const int unknowns = options.metric_camera ? 3 : 4;
    Eigen::MatrixXd m(3 * pairs.size(), unknowns);
    Eigen::VectorXd rhs(3 * pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      const Eigen::Matrix3d ra = pairs[i].base_motion.RotationMatrix();
      const Eigen::Vector3d tb = rx * pairs[i].cam_motion.translation;
      m.block<3, 3>(3 * static_cast<Eigen::Index>(i), 0) = ra - Eigen::Matrix3d::Identity();
      if (options.metric_camera) {
        rhs.segment<3>(3 * static_cast<Eigen::Index>(i)) = tb - pairs[i].base_motion.translation;
      } else {
        m.block<3, 1>(3 * static_cast<Eigen::Index>(i), 3) = -tb;
        rhs.segment<3>(3 * static_cast<Eigen::Index>(i)) = -pairs[i].base_motion.translation;
      }
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> lsq(m, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = lsq.singularValues();
    if (sv(sv.size() - 1) < 1e-9 * std::max(1.0, sv(0))) {
      return Status::Error("hand-eye: translation and scale are not determined by these motions "
                           "(the robot must both turn and move)");
    }
    const Eigen::VectorXd x = lsq.solve(rhs);
    tx = x.head<3>();
    if (!options.metric_camera) scale = x(3);
    std::ostringstream os;
    os << "general motion (turn axes spread " << max_dev / kDegToRad
       << " deg): rotation, translation" << (options.metric_camera ? "" : " and scale") << " observable";
    r.observability = os.str();
  } else {
    // The camera's view of the turn axis: mean of the b vectors (signs follow a).
    Eigen::Vector3d m_cam = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& v : b) m_cam += v.normalized();
    if (m_cam.norm() < 1e-9) return Status::Error("hand-eye: camera rotations are inconsistent");
    const Eigen::Matrix3d r0 =
        Eigen::Quaterniond::FromTwoVectors(m_cam.normalized(), n).toRotationMatrix();
    // Everything in a basis P = [e1 e2 n] of the base frame.
    const Eigen::Matrix3d p = BasisWithThirdAxis(n);
    Eigen::MatrixXd m(2 * pairs.size(), 4);
    Eigen::VectorXd rhs(2 * pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) {
      const Eigen::Matrix3d ra = p.transpose() * pairs[i].base_motion.RotationMatrix() * p;
      const Eigen::Vector3d ta = p.transpose() * pairs[i].base_motion.translation;
      const Eigen::Vector3d u = p.transpose() * r0 * pairs[i].cam_motion.translation;
      const Eigen::Index row = 2 * static_cast<Eigen::Index>(i);
      // (Ra - I)_xy t_xy - [c -d; d c] u_xy = -ta_xy, unknowns (t_x, t_y, c, d).
      m.block<2, 2>(row, 0) = ra.topLeftCorner<2, 2>() - Eigen::Matrix2d::Identity();
      m(row, 2) = -u.x();
      m(row, 3) = u.y();
      m(row + 1, 2) = -u.y();
      m(row + 1, 3) = -u.x();
      rhs.segment<2>(row) = -ta.head<2>();
    }
    Eigen::JacobiSVD<Eigen::MatrixXd> lsq(m, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = lsq.singularValues();
    if (sv(3) < 1e-9 * std::max(1.0, sv(0))) {
      return Status::Error("hand-eye (planar): translation, scale and the angle about the turn "
                           "axis are not determined: the robot must both drive and turn");
    }
    const Eigen::Vector4d x = lsq.solve(rhs);
    const double c = x(2), d = x(3);
    scale = std::hypot(c, d);
    const double theta = std::atan2(d, c);
    rx = p * Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()).toRotationMatrix() * p.transpose() * r0;
    tx = p * Eigen::Vector3d(x(0), x(1), options.prior_offset_along_axis_m);
    if (options.metric_camera) scale = 1.0;
    std::ostringstream os;
    os << "planar motion (turn axes within " << max_dev / kDegToRad << " deg of one axis): rotation, "
       << "translation across the axis" << (options.metric_camera ? "" : " and scale")
       << " observable; the offset ALONG the axis is not and was set to the prior "
       << options.prior_offset_along_axis_m << " m";
    r.observability = os.str();
  }
  r.base_from_cam = Rigid3d(rx, tx);
  r.scale = scale;
  r.axis_in_base = n;
  for (const MotionPair& pair : pairs) {
    const Eigen::Matrix3d ra = pair.base_motion.RotationMatrix();
    const Eigen::Matrix3d rb = pair.cam_motion.RotationMatrix();
    r.rotation_residuals_rad.push_back(LogSO3((ra * rx).transpose() * rx * rb).norm());
    r.translation_residuals_m.push_back(
        ((ra - Eigen::Matrix3d::Identity()) * tx + pair.base_motion.translation -
         scale * (rx * pair.cam_motion.translation))
            .norm());
  }
  r.rotation_rms_rad = Rms(r.rotation_residuals_rad);
  r.translation_rms_m = Rms(r.translation_residuals_m);
  *result = r;
  return Status::Ok();
}

Status BuildMotionPairs(const std::vector<TimedPose>& world_from_cam,
                        const std::vector<TimedPose>& odom_from_base, const PairingOptions& options,
                        std::vector<MotionPair>* pairs, int* outside) {
  pairs->clear();
  *outside = 0;
  PoseBuffer odometry(SecondsToUtime(options.max_gap_s), odom_from_base.size() + 1);
  for (const TimedPose& p : odom_from_base) {
    MBSLAM_RETURN_IF_ERROR(odometry.Insert(p.utime, p.pose).WithContext("odometry"));
  }
  // Camera poses with their interpolated odometry.
  std::vector<std::pair<TimedPose, Rigid3d>> matched;
  for (const TimedPose& c : world_from_cam) {
    Rigid3d base;
    if (odometry.Interpolate(c.utime, &base) != InterpolationResult::kOk) {
      ++*outside;
      continue;
    }
    matched.emplace_back(c, base);
  }
  const int64_t max_duration = SecondsToUtime(options.max_duration_s);
  size_t k = 0;
  while (k + 1 < matched.size()) {
    size_t j = k + 1;
    for (; j < matched.size(); ++j) {
      const Rigid3d a = matched[k].second.Inverse() * matched[j].second;
      if (LogSO3(a.RotationMatrix()).norm() >= options.min_rotation_deg * kDegToRad ||
          a.translation.norm() >= options.min_translation_m) {
        break;
      }
    }
    if (j >= matched.size()) break;
    if (matched[j].first.utime - matched[k].first.utime <= max_duration) {
      MotionPair pair;
      pair.utime0 = matched[k].first.utime;
      pair.utime1 = matched[j].first.utime;
      pair.base_motion = matched[k].second.Inverse() * matched[j].second;
      pair.cam_motion = matched[k].first.pose.Inverse() * matched[j].first.pose;
      pairs->push_back(pair);
    }
    k = j;
  }
  return Status::Ok();
}

}  // namespace mbslam
