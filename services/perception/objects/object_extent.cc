#include "services/perception/objects/object_extent.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mbslam {
namespace {

// Linear-interpolated percentile of sorted values, q in [0, 1].
double SortedPercentile(const std::vector<double>& sorted, double q) {
  if (sorted.empty()) return 0.0;
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const size_t i = static_cast<size_t>(std::floor(pos));
  const size_t j = std::min(i + 1, sorted.size() - 1);
  const double f = pos - static_cast<double>(i);
  return sorted[i] * (1.0 - f) + sorted[j] * f;
}

}  // namespace

Eigen::Vector3d ObjectExtent::HalfSizeAlong(const Eigen::Matrix3d& world_from_axes) const {
  if (!valid) return Eigen::Vector3d::Zero();
  const Eigen::Matrix3d box = world_from_box.toRotationMatrix();
  // |axes^T box| times the half sizes: the support of the box along each axis.
  const Eigen::Matrix3d a = (world_from_axes.transpose() * box).cwiseAbs();
  return a * (0.5 * size);
}

ObjectExtentEstimator::ObjectExtentEstimator(const ObjectExtentOptions& options)
    : options_(options) {}

void ObjectExtentEstimator::Reset() {
  extent_ = ObjectExtent();
  offset_in_box_.setZero();
  num_updates_ = 0;
}

void ObjectExtentEstimator::RescaleWorld(double factor) {
  if (!(factor > 0.0) || !std::isfinite(factor)) return;
  extent_.size *= factor;
  extent_.center_offset *= factor;
  offset_in_box_ *= factor;
}

Status ObjectExtentEstimator::Update(const Rigid3d& cam_from_world,
                                     const std::vector<Eigen::Vector2d>& track_xy,
                                     const Eigen::Vector2d& reference_xy, double depth,
                                     const Eigen::Vector3d& up) {
  if (!options_.Check()) return Status::Error("object extent options: " + LastOptionError());
  if (!cam_from_world.IsFinite() || !reference_xy.allFinite() || !std::isfinite(depth) ||
      depth <= 0.0 || !up.allFinite() || up.norm() < 1e-12) {
    return Status::Error("ObjectExtentEstimator: non-finite pose, bearing, depth or up");
  }
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  const Eigen::Matrix3d R_wc = world_from_cam.RotationMatrix();
  const Eigen::Vector3d z_axis = up.normalized();
  Eigen::Vector3d x_axis = R_wc.col(2) - R_wc.col(2).dot(z_axis) * z_axis;
  if (x_axis.norm() < 1e-6) {  // looking straight down or up: use the image's "up"
    x_axis = -R_wc.col(1) - (-R_wc.col(1)).dot(z_axis) * z_axis;
  }
  if (x_axis.norm() < 1e-6) return Status::Error("ObjectExtentEstimator: degenerate view");
  x_axis.normalize();
  const Eigen::Vector3d y_axis = z_axis.cross(x_axis);
  Eigen::Matrix3d box;
  box << x_axis, y_axis, z_axis;

  std::vector<double> lateral, height;
  lateral.reserve(track_xy.size());
  height.reserve(track_xy.size());
  for (const Eigen::Vector2d& xy : track_xy) {
    if (!xy.allFinite()) continue;
    const Eigen::Vector3d p = R_wc * (depth * xy.homogeneous());  // relative to the camera
    lateral.push_back(y_axis.dot(p));
    height.push_back(z_axis.dot(p));
  }
  if (static_cast<int>(lateral.size()) < options_.min_tracks) {
    return Status::Error("ObjectExtentEstimator: " + std::to_string(lateral.size()) +
                         " tracks, need " + std::to_string(options_.min_tracks));
  }
  std::sort(lateral.begin(), lateral.end());
  std::sort(height.begin(), height.end());
  const double lo = options_.low_percentile, hi = options_.high_percentile;
  const double spread = hi - lo;
  const double y_lo = SortedPercentile(lateral, lo), y_hi = SortedPercentile(lateral, hi);
  const double z_lo = SortedPercentile(height, lo), z_hi = SortedPercentile(height, hi);
  const auto clamp_size = [&](double s) {
    return std::clamp(s, options_.min_size, options_.max_size);
  };
  const double width = clamp_size((y_hi - y_lo) / spread);
  const double tall = clamp_size((z_hi - z_lo) / spread);
  const double deep = clamp_size(options_.depth_to_width_ratio * width);
  const Eigen::Vector3d size(deep, width, tall);

  // Offset of the box centre from the reference point, in box coordinates: the middle of
  // the percentile ranges across and up, half the depth behind the visible face.
  const Eigen::Vector3d ref = R_wc * (depth * reference_xy.homogeneous());
  const Eigen::Vector3d offset(0.5 * deep, 0.5 * (y_lo + y_hi) - y_axis.dot(ref),
                               0.5 * (z_lo + z_hi) - z_axis.dot(ref));

  if (num_updates_ == 0) {
    extent_.size = size;
    offset_in_box_ = offset;
  } else {
    const double g = options_.smoothing;
    extent_.size = (1.0 - g) * extent_.size + g * size;
    offset_in_box_ = (1.0 - g) * offset_in_box_ + g * offset;
  }
  extent_.world_from_box = Eigen::Quaterniond(box).normalized();
  extent_.center_offset = box * offset_in_box_;
  extent_.valid = true;
  ++num_updates_;
  return Status::Ok();
}

}  // namespace mbslam
