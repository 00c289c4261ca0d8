#include "tools/eval/plot.h"

#include <Eigen/Eigenvalues>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mbslam {
namespace eval {
namespace {

// A "nice" grid spacing (1, 2 or 5 times a power of ten) giving about `lines` lines.
double NiceStep(double range, int lines) {
  const double raw = range / std::max(1, lines);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) {
      return m * p;
    }
  }
  return 10.0 * p;
}

}  // namespace

Status DrawTopView(const Trajectory& gt, const Trajectory& est_aligned, const TopViewPlot& o,
                   cv::Mat* image) {
  if (gt.empty() && est_aligned.empty()) {
    return Status::Error("plot: nothing to draw");
  }
  // Plane of the ground truth's two main directions (PCA); fall back to the estimate.
  const Trajectory& ref = gt.size() >= 2 ? gt : est_aligned;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : ref) {
    mean += p.pose.translation;
  }
  mean /= static_cast<double>(ref.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : ref) {
    const Eigen::Vector3d d = p.pose.translation - mean;
    cov += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d e1 = eig.eigenvectors().col(2), e2 = eig.eigenvectors().col(1);
  if (eig.eigenvalues()(2) < 1e-18) {  // no motion at all: any plane will do
    e1 = Eigen::Vector3d::UnitX();
    e2 = Eigen::Vector3d::UnitY();
  }
  auto to2d = [&](const Eigen::Vector3d& p) {
    return Eigen::Vector2d((p - mean).dot(e1), (p - mean).dot(e2));
  };
  Eigen::AlignedBox2d box;
  for (const auto& p : gt) {
    box.extend(to2d(p.pose.translation));
  }
  for (const auto& p : est_aligned) {
    box.extend(to2d(p.pose.translation));
  }
  const double extent = std::max({box.sizes().x(), box.sizes().y(), 1e-3});
  box.min() -= Eigen::Vector2d::Constant(0.08 * extent);
  box.max() += Eigen::Vector2d::Constant(0.08 * extent);
  const int margin_top = 50, margin = 30;
  const double sx = (o.width - 2 * margin) / box.sizes().x();
  const double sy = (o.height - margin - margin_top) / box.sizes().y();
  const double s = std::min(sx, sy);
  const Eigen::Vector2d c = box.center();
  auto px = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector2d q = to2d(p);
    return cv::Point2d(o.width / 2.0 + s * (q.x() - c.x()),
                       margin_top + (o.height - margin_top - margin) / 2.0 - s * (q.y() - c.y()));
  };
  *image = cv::Mat(o.height, o.width, CV_8UC3, cv::Scalar(255, 255, 255));
  // Grid.
  const double step = NiceStep(std::max(box.sizes().x(), box.sizes().y()), 8);
  const cv::Scalar grid(225, 225, 225);
  for (double x = std::floor(box.min().x() / step) * step; x <= box.max().x(); x += step) {
    const int u = static_cast<int>(std::lround(o.width / 2.0 + s * (x - c.x())));
    cv::line(*image, cv::Point(u, margin_top), cv::Point(u, o.height - margin), grid, 1);
  }
  for (double y = std::floor(box.min().y() / step) * step; y <= box.max().y(); y += step) {
    const int v = static_cast<int>(
        std::lround(margin_top + (o.height - margin_top - margin) / 2.0 - s * (y - c.y())));
    cv::line(*image, cv::Point(margin, v), cv::Point(o.width - margin, v), grid, 1);
  }
  const int shift = 4;  // sub-pixel drawing
  auto fixed = [&](const cv::Point2d& p) {
    return cv::Point(cvRound(p.x * 16.0), cvRound(p.y * 16.0));
  };
  if (o.draw_errors && !gt.empty()) {
    for (const auto& e : est_aligned) {
      auto it = std::lower_bound(gt.begin(), gt.end(), e.utime,
                                 [](const TimedPose& p, int64_t t) { return p.utime < t; });
      if (it == gt.end() || it->utime != e.utime) {
        // nearest in time
        if (it == gt.end() ||
            (it != gt.begin() && e.utime - std::prev(it)->utime < it->utime - e.utime)) {
          --it;
        }
      }
      cv::line(*image, fixed(px(e.pose.translation)), fixed(px(it->pose.translation)),
               cv::Scalar(190, 190, 190), 1, cv::LINE_AA, shift);
    }
  }
  auto polyline = [&](const Trajectory& t, const cv::Scalar& color) {
    for (size_t i = 1; i < t.size(); ++i) {
      cv::line(*image, fixed(px(t[i - 1].pose.translation)), fixed(px(t[i].pose.translation)),
               color, 2, cv::LINE_AA, shift);
    }
    if (!t.empty()) {
      cv::circle(*image, fixed(px(t.front().pose.translation)), 5 * 16, color, 2, cv::LINE_AA,
                 shift);
    }
  };
  const cv::Scalar green(40, 160, 40), red(40, 40, 220);
  polyline(gt, green);
  polyline(est_aligned, red);
  // Title, legend, grid size.
  cv::putText(*image, o.title, cv::Point(margin, 22), cv::FONT_HERSHEY_SIMPLEX, 0.55,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "grid %g m", step);
  cv::putText(*image, buf, cv::Point(margin, 42), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              cv::Scalar(90, 90, 90), 1, cv::LINE_AA);
  cv::line(*image, cv::Point(o.width - 230, 18), cv::Point(o.width - 200, 18), green, 2);
  cv::putText(*image, "ground truth", cv::Point(o.width - 195, 23), cv::FONT_HERSHEY_SIMPLEX, 0.45,
              green, 1, cv::LINE_AA);
  cv::line(*image, cv::Point(o.width - 230, 38), cv::Point(o.width - 200, 38), red, 2);
  cv::putText(*image, "estimate (aligned)", cv::Point(o.width - 195, 43), cv::FONT_HERSHEY_SIMPLEX,
              0.45, red, 1, cv::LINE_AA);
  return Status::Ok();
}

Status WriteTopView(const std::string& path, const Trajectory& gt, const Trajectory& est_aligned,
                    const TopViewPlot& options) {
  cv::Mat image;
  MBSLAM_RETURN_IF_ERROR(DrawTopView(gt, est_aligned, options, &image));
  try {
    if (!cv::imwrite(path, image)) {
      return Status::Error("cannot write " + path);
    }
  } catch (const cv::Exception& e) {
    return Status::Error("cannot write " + path + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace eval
}  // namespace mbslam
