#include "tools/sim/gt_check.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "common/util/logging.h"

namespace mbslam {
namespace sim {
namespace {

struct FrameContext {
  const Simulator& sim;
  const SimFrame& frame;
  const CameraIntrinsics& K;
  RayCaster caster;
  std::vector<Rigid3d> world_from_body;  // per scene body index
  Rigid3d cam_from_world;

  FrameContext(const Simulator& s, const SimFrame& f)
      : sim(s), frame(f), K(s.intrinsics()), caster(s.scene()) {
    for (const auto& b : s.scene().bodies) {
      world_from_body.push_back(s.WorldFromBody(b.id, f.utime));
    }
    cam_from_world = f.world_from_cam.Inverse();
  }

  // Unit ray through pixel (u, v) in the camera frame.
  Eigen::Vector3d RayInCam(double u, double v) const {
    return Eigen::Vector3d((u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.0).normalized();
  }
  RayHit Cast(double u, double v) const {
    return caster.Cast(world_from_body, frame.world_from_cam.translation,
                       frame.world_from_cam.rotation * RayInCam(u, v));
  }
  // Body id the geometry shows at pixel (u, v): 0 for the static world and for sky.
  int IdAt(double u, double v) const {
    const RayHit hit = Cast(u, v);
    return hit.body_index < 0 ? 0 : sim.scene().bodies[static_cast<size_t>(hit.body_index)].id;
  }
  bool Inside(int x, int y) const { return x >= 0 && y >= 0 && x < K.width && y < K.height; }
  int MaskAt(int x, int y) const { return frame.mask.at<uint16_t>(y, x); }
};

// Distance from (u, v) to the square of pixel (x, y).
double DistanceToPixel(double u, double v, int x, int y) {
  const double dx = std::max(0.0, std::abs(u - x) - 0.5);
  const double dy = std::max(0.0, std::abs(v - y) - 0.5);
  return std::hypot(dx, dy);
}

}  // namespace

void GtCheckReport::Merge(const GtCheckReport& o) {
  const double sum_sq =
      reprojection_rms_px * reprojection_rms_px * static_cast<double>(reprojection_samples) +
      o.reprojection_rms_px * o.reprojection_rms_px * static_cast<double>(o.reprojection_samples);
  frames += o.frames;
  samples_visible += o.samples_visible;
  samples_visible_moving += o.samples_visible_moving;
  label_failures += o.label_failures;
  label_max_px = std::max(label_max_px, o.label_max_px);
  reprojection_samples += o.reprojection_samples;
  reprojection_max_px = std::max(reprojection_max_px, o.reprojection_max_px);
  reprojection_rms_px = reprojection_samples > 0
                            ? std::sqrt(sum_sq / static_cast<double>(reprojection_samples))
                            : 0.0;
  surface_max_distance_m = std::max(surface_max_distance_m, o.surface_max_distance_m);
  depth_at_sample_max_rel = std::max(depth_at_sample_max_rel, o.depth_at_sample_max_rel);
  pixels += o.pixels;
  pixel_label_mismatches += o.pixel_label_mismatches;
  pixel_label_mismatches_on_edges += o.pixel_label_mismatches_on_edges;
  pixel_depth_skipped_on_edges += o.pixel_depth_skipped_on_edges;
  pixel_depth_grazing += o.pixel_depth_grazing;
  depth_max_error_px = std::max(depth_max_error_px, o.depth_max_error_px);
  depth_max_abs_error_m = std::max(depth_max_abs_error_m, o.depth_max_abs_error_m);
  depth_max_rel_error = std::max(depth_max_rel_error, o.depth_max_rel_error);
  pixel_backprojection_max_px =
      std::max(pixel_backprojection_max_px, o.pixel_backprojection_max_px);
}

std::string GtCheckReport::ToJson() const {
  std::ostringstream out;
  out << std::setprecision(6);
  out << "{\"frames\": " << frames << ", \"gt_reprojection_max_px\": " << MaxErrorPx()
      << ", \"samples_visible\": " << samples_visible
      << ", \"samples_visible_moving\": " << samples_visible_moving
      << ", \"label_failures\": " << label_failures << ", \"label_max_px\": " << label_max_px
      << ", \"reprojection_samples\": " << reprojection_samples
      << ", \"reprojection_max_px\": " << reprojection_max_px
      << ", \"reprojection_rms_px\": " << reprojection_rms_px
      << ", \"surface_max_distance_m\": " << surface_max_distance_m
      << ", \"depth_at_sample_max_rel\": " << depth_at_sample_max_rel << ", \"pixels\": " << pixels
      << ", \"pixel_label_mismatches\": " << pixel_label_mismatches
      << ", \"pixel_label_mismatches_on_edges\": " << pixel_label_mismatches_on_edges
      << ", \"pixel_depth_skipped_on_edges\": " << pixel_depth_skipped_on_edges
      << ", \"pixel_depth_grazing\": " << pixel_depth_grazing
      << ", \"depth_max_error_px\": " << depth_max_error_px
      << ", \"depth_max_abs_error_m\": " << depth_max_abs_error_m
      << ", \"depth_max_rel_error\": " << depth_max_rel_error
      << ", \"pixel_backprojection_max_px\": " << pixel_backprojection_max_px << "}";
  return out.str();
}

Status CheckFrameGroundTruth(const Simulator& sim, const SimFrame& frame,
                             const GtCheckOptions& options, GtCheckReport* report) {
  if (!options.Check()) {
    return Status::Error("gt check options: " + LastOptionError());
  }
  if (frame.mask.empty() || frame.points_in_cam.empty() || frame.depth.empty()) {
    return Status::Error("gt check: the frame was rendered without geometry");
  }
  const FrameContext ctx(sim, frame);
  const CameraIntrinsics& K = ctx.K;
  GtCheckReport r;
  r.frames = 1;
  double reprojection_sum_sq = 0.0;

  // 1. Ground-truth surface samples of every body.
  const auto& bodies = sim.scene().bodies;
  for (size_t b = 0; b < bodies.size(); ++b) {
    const int id = bodies[b].id;
    const auto& points = sim.SurfacePoints(id);
    if (points.empty()) {
      continue;
    }
    const size_t step =
        std::max<size_t>(1, points.size() / static_cast<size_t>(options.max_samples_per_body));
    const Rigid3d cam_from_body = ctx.cam_from_world * ctx.world_from_body[b];
    for (size_t i = 0; i < points.size(); i += step) {
      const Eigen::Vector3d X = cam_from_body * points[i];
      if (X.z() < 0.2) {
        continue;
      }
      const Eigen::Vector2d uv = K.Project(X);
      if (!K.InImage(uv, options.border_px)) {
        continue;
      }
      // Visible iff the ray through the projection hits this body at this distance.
      const RayHit hit = ctx.Cast(uv.x(), uv.y());
      if (hit.body_index != static_cast<int>(b) ||
          std::abs(hit.distance - X.norm()) > 1e-6 * X.norm() + 1e-7) {
        continue;
      }
      const int cx = static_cast<int>(std::lround(uv.x())),
                cy = static_cast<int>(std::lround(uv.y()));
      // Resolvable at this image resolution: the body covers the centre of a pixel whose
      // square is within half a pixel of the projection (not a sub-pixel sliver).
      bool resolvable = false;
      for (int dy = -1; dy <= 1 && !resolvable; ++dy) {
        for (int dx = -1; dx <= 1 && !resolvable; ++dx) {
          resolvable = ctx.Inside(cx + dx, cy + dy) &&
                       DistanceToPixel(uv.x(), uv.y(), cx + dx, cy + dy) <= 0.5 &&
                       ctx.IdAt(cx + dx, cy + dy) == id;
        }
      }
      if (!resolvable) {
        continue;
      }
      ++r.samples_visible;
      if (id > 0) {
        ++r.samples_visible_moving;
      }
      double label_error = 2.0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (ctx.Inside(cx + dx, cy + dy) && ctx.MaskAt(cx + dx, cy + dy) == id) {
            label_error = std::min(label_error, DistanceToPixel(uv.x(), uv.y(), cx + dx, cy + dy));
          }
        }
      }
      r.label_max_px = std::max(r.label_max_px, label_error);
      if (label_error > 0.5) {
        ++r.label_failures;
        std::ostringstream msg;
        msg << "label failure: body " << id << " at (" << uv.x() << ", " << uv.y() << ") z "
            << X.z() << " mask/ray:";
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            if (ctx.Inside(cx + dx, cy + dy)) {
              msg << " " << ctx.MaskAt(cx + dx, cy + dy) << "/" << ctx.IdAt(cx + dx, cy + dy);
            }
          }
        }
        MBSLAM_LOG(DEBUG) << msg.str();
      }

      // Where did the renderer draw this point? Fit P(x, y) = A [x y 1]^T to the rendered
      // points of the 3x3 neighbourhood; skip neighbourhoods that are not one plane.
      if (cx < 1 || cy < 1 || cx >= K.width - 1 || cy >= K.height - 1) {
        continue;
      }
      Eigen::Matrix<double, 9, 3> design;
      Eigen::Matrix<double, 9, 3> rendered;
      bool uniform = true;
      int row = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx, ++row) {
          uniform = uniform && ctx.MaskAt(cx + dx, cy + dy) == id;
          const cv::Vec3f p = frame.points_in_cam.at<cv::Vec3f>(cy + dy, cx + dx);
          design.row(row) << cx + dx, cy + dy, 1.0;
          rendered.row(row) << p[0], p[1], p[2];
        }
      }
      if (!uniform) {
        continue;
      }
      const Eigen::Matrix3d A =
          design.colPivHouseholderQr().solve(rendered).transpose();  // 3x3: P = A [x y 1]
      const double fit_rms = std::sqrt((design * A.transpose() - rendered).squaredNorm() / 9.0);
      if (fit_rms > 2e-5 * X.z() + 1e-6) {
        continue;  // two faces meet here
      }
      // Pixel (x, y) where the fitted surface comes closest to X.
      const Eigen::Matrix<double, 3, 2> J = A.leftCols<2>();
      const Eigen::Vector2d xy = (J.transpose() * J).ldlt().solve(J.transpose() * (X - A.col(2)));
      const Eigen::Vector3d on_surface = J * xy + A.col(2);
      const double err = (xy - uv).norm();
      ++r.reprojection_samples;
      reprojection_sum_sq += err * err;
      r.reprojection_max_px = std::max(r.reprojection_max_px, err);
      r.surface_max_distance_m = std::max(r.surface_max_distance_m, (on_surface - X).norm());
      const double depth_here = (A * Eigen::Vector3d(uv.x(), uv.y(), 1.0)).z();
      r.depth_at_sample_max_rel =
          std::max(r.depth_at_sample_max_rel, std::abs(depth_here - X.z()) / X.z());
    }
  }
  r.reprojection_rms_px =
      r.reprojection_samples > 0
          ? std::sqrt(reprojection_sum_sq / static_cast<double>(r.reprojection_samples))
          : 0.0;

  // 2. A grid of pixel centres against ray casts.
  for (int y = 0; y < K.height; y += options.pixel_stride) {
    for (int x = 0; x < K.width; x += options.pixel_stride) {
      ++r.pixels;
      const Eigen::Vector3d ray = ctx.RayInCam(x, y);
      const RayHit hit = ctx.Cast(x, y);
      const int expected_id =
          hit.body_index < 0 ? 0 : bodies[static_cast<size_t>(hit.body_index)].id;
      const double expected_depth = hit.body_index < 0 ? 0.0 : hit.distance * ray.z();
      const int rendered_id = ctx.MaskAt(x, y);
      const double rendered_depth = frame.depth.at<float>(y, x);
      auto agrees = [&](int id, double depth) {
        return id == rendered_id && (depth > 0.0) == (rendered_depth > 0.0) &&
               std::abs(depth - rendered_depth) <= 1e-3 * depth + 1e-6;
      };
      if (!agrees(expected_id, expected_depth)) {
        // A pixel centre (almost) on a silhouette or on a quad's border: a ray a hair
        // away (0.02 px) shows what was rendered. Anything else is a real mismatch.
        bool on_edge = false;
        const double d = 0.02;
        const double offsets[4][2] = {{d, 0}, {-d, 0}, {0, d}, {0, -d}};
        for (const auto& o : offsets) {
          const RayHit h = ctx.Cast(x + o[0], y + o[1]);
          const Eigen::Vector3d ray_o = ctx.RayInCam(x + o[0], y + o[1]);
          const int id_o = h.body_index < 0 ? 0 : bodies[static_cast<size_t>(h.body_index)].id;
          on_edge = on_edge || agrees(id_o, h.body_index < 0 ? 0.0 : h.distance * ray_o.z());
        }
        if (rendered_id != expected_id) {
          ++r.pixel_label_mismatches;
          if (on_edge) {
            ++r.pixel_label_mismatches_on_edges;
          }
          continue;
        }
        if (on_edge) {
          ++r.pixel_depth_skipped_on_edges;
          continue;
        }
        MBSLAM_LOG(DEBUG) << "depth mismatch at (" << x << ", " << y << "): body " << expected_id
                          << " rendered " << rendered_depth << " m, ray cast " << expected_depth
                          << " m";
      }
      if (expected_depth <= 0.0) {
        continue;
      }
      const double abs_err = std::abs(rendered_depth - expected_depth);
      if (abs_err > 1e-5 * expected_depth) {
        // How far in the image is this depth error? Surfaces seen at grazing angles
        // (far ground) change depth by metres per pixel, so there a tiny sub-pixel
        // difference of the rasteriser shows as a large relative depth error.
        double per_px = 0.0;
        const double h = 0.25;
        const double steps[2][2] = {{h, 0.0}, {0.0, h}};
        for (const auto& st : steps) {
          const RayHit a = ctx.Cast(x + st[0], y + st[1]), b = ctx.Cast(x - st[0], y - st[1]);
          if (a.body_index < 0 || b.body_index < 0) {
            continue;
          }
          const double za = a.distance * ctx.RayInCam(x + st[0], y + st[1]).z();
          const double zb = b.distance * ctx.RayInCam(x - st[0], y - st[1]).z();
          per_px = std::max(per_px, std::abs(za - zb) / (2.0 * h));
        }
        if (per_px > 0.0) {
          r.depth_max_error_px = std::max(r.depth_max_error_px, abs_err / per_px);
        }
        if (per_px > 0.01 * expected_depth) {
          ++r.pixel_depth_grazing;
          continue;
        }
      }
      r.depth_max_abs_error_m = std::max(r.depth_max_abs_error_m, abs_err);
      r.depth_max_rel_error = std::max(r.depth_max_rel_error, abs_err / expected_depth);
      const cv::Vec3f p = frame.points_in_cam.at<cv::Vec3f>(y, x);
      const Eigen::Vector2d back = K.Project(Eigen::Vector3d(p[0], p[1], p[2]));
      r.pixel_backprojection_max_px =
          std::max(r.pixel_backprojection_max_px, (back - Eigen::Vector2d(x, y)).norm());
    }
  }
  report->Merge(r);
  return Status::Ok();
}

}  // namespace sim
}  // namespace mbslam
