#include "services/perception/occupancy/dense_rays.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <unordered_map>

#include "services/perception/geometry/polygon.h"

namespace mbslam {
namespace {

// A projected point: image position (px, relative to the principal point), depth and
// position in the camera frame.
struct Vertex {
  Eigen::Vector2d px;
  double inv_depth = 0.0;
  Eigen::Vector3d in_cam;
};

struct Triangle {
  int a = 0, b = 0, c = 0;
  double longest_px = 0.0;
  double max_depth = 0.0;
};

uint64_t CoordKey(float x, float y) {
  uint32_t bx = 0, by = 0;
  std::memcpy(&bx, &x, sizeof(bx));
  std::memcpy(&by, &y, sizeof(by));
  return (static_cast<uint64_t>(bx) << 32) | by;
}

// A moving object's hull grown by a margin, with its bounding box for a quick test.
struct GrownHull {
  std::vector<Eigen::Vector2f> points;
  Eigen::Vector2f lo, hi;
  bool Contains(const Eigen::Vector2d& p) const {
    const Eigen::Vector2f q = p.cast<float>();
    if ((q.array() < lo.array()).any() || (q.array() > hi.array()).any()) return false;
    return InsideConvexHull(points, q);
  }
};

std::vector<GrownHull> GrowHulls(const std::vector<std::vector<Eigen::Vector2d>>& hulls_xy, double focal_px,
                                 double margin_px) {
  std::vector<GrownHull> out;
  for (const std::vector<Eigen::Vector2d>& h : hulls_xy) {
    if (h.size() < 3) continue;
    std::vector<Eigen::Vector2f> px;
    px.reserve(h.size());
    for (const Eigen::Vector2d& p : h) {
      if (p.allFinite()) px.push_back((focal_px * p).cast<float>());
    }
    px = ConvexHull(std::move(px));
    if (px.size() < 3) continue;
    Eigen::Vector2f c = Eigen::Vector2f::Zero();
    for (const Eigen::Vector2f& p : px) c += p;
    c /= static_cast<float>(px.size());
    GrownHull g;
    g.lo = g.hi = px.front();
    for (const Eigen::Vector2f& p : px) {
      const Eigen::Vector2f d = p - c;
      const float n = d.norm();
      const Eigen::Vector2f q = n > 0.0f ? Eigen::Vector2f(c + d * (1.0f + static_cast<float>(margin_px) / n)) : p;
      g.points.push_back(q);
      g.lo = g.lo.cwiseMin(q);
      g.hi = g.hi.cwiseMax(q);
    }
    out.push_back(std::move(g));
  }
  return out;
}

// True if p is inside triangle (a, b, c) (either orientation, edges included).
bool InTriangle(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                const Eigen::Vector2d& c) {
  auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
  const double d1 = cross(b - a, p - a), d2 = cross(c - b, p - b), d3 = cross(a - c, p - c);
  const bool has_neg = d1 < 0 || d2 < 0 || d3 < 0;
  const bool has_pos = d1 > 0 || d2 > 0 || d3 > 0;
  return !(has_neg && has_pos);
}

}  // namespace

double TriangulationDepthSigma(const Eigen::Vector3d& point, const Eigen::Vector3d& view_center,
                               const std::vector<Eigen::Vector3d>& centers, double bearing_sigma_rad) {
  const Eigen::Vector3d ray = point - view_center;
  const double depth = ray.norm();
  double best_sin = 0.0;
  for (const Eigen::Vector3d& c : centers) {
    const Eigen::Vector3d other = point - c;
    const double n = depth * other.norm();
    if (!(n > 0.0)) continue;
    // The angle between the rays, up to 90 deg (wider angles constrain no worse).
    const double cos_angle = ray.dot(other) / n;
    const double sin_angle = cos_angle <= 0.0 ? 1.0 : ray.cross(other).norm() / n;
    best_sin = std::max(best_sin, sin_angle);
  }
  if (!(best_sin > 0.0) || !std::isfinite(depth)) return std::numeric_limits<double>::infinity();
  return depth * bearing_sigma_rad / best_sin;
}

std::vector<Eigen::Vector3d> DensifyKeyframe(const DenseRayInput& input, const DenseRayOptions& options,
                                             DenseRayStats* stats) {
  DenseRayStats local;
  DenseRayStats& st = stats ? *stats : local;
  st = DenseRayStats();
  std::vector<Eigen::Vector3d> samples;
  if (!options.enabled || !(input.voxel > 0.0) || !(input.focal_px > 0.0) ||
      !std::isfinite(input.voxel) || !std::isfinite(input.focal_px)) {
    return samples;
  }
  const double f = input.focal_px;

  // Project the points; one vertex per image position.
  std::vector<Vertex> vertices;
  vertices.reserve(input.points_in_world.size());
  std::unordered_map<uint64_t, int> vertex_of;
  vertex_of.reserve(input.points_in_world.size() * 2);
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  // Image positions far outside any image are not plausible projections (px).
  constexpr double kMaxImageCoord = 1e5;
  const bool use_sigma = options.max_depth_sigma_voxels > 0.0 &&
                         input.depth_sigma.size() == input.points_in_world.size();
  const double max_sigma = options.max_depth_sigma_voxels * input.voxel;
  for (size_t i = 0; i < input.points_in_world.size(); ++i) {
    const Eigen::Vector3d& p = input.points_in_world[i];
    if (!p.allFinite()) continue;
    if (use_sigma && !(input.depth_sigma[i] <= max_sigma)) {
      ++st.uncertain;
      continue;
    }
    const Eigen::Vector3d c = input.cam_from_world * p;
    if (!(c.z() >= options.min_depth)) continue;
    Vertex v;
    v.px = f * Eigen::Vector2d(c.x() / c.z(), c.y() / c.z());
    if (!(v.px.cwiseAbs().maxCoeff() < kMaxImageCoord)) continue;
    v.inv_depth = 1.0 / c.z();
    v.in_cam = c;
    const float fx = static_cast<float>(v.px.x()), fy = static_cast<float>(v.px.y());
    if (!vertex_of.emplace(CoordKey(fx, fy), static_cast<int>(vertices.size())).second) continue;
    v.px = Eigen::Vector2d(fx, fy);  // the position the triangulation sees
    lo = lo.cwiseMin(v.px);
    hi = hi.cwiseMax(v.px);
    vertices.push_back(v);
  }
  st.points = static_cast<int>(vertices.size());
  if (st.points < std::max(3, options.min_points)) return samples;

  const cv::Rect rect(static_cast<int>(std::floor(lo.x())) - 2, static_cast<int>(std::floor(lo.y())) - 2,
                      static_cast<int>(std::ceil(hi.x() - lo.x())) + 5, static_cast<int>(std::ceil(hi.y() - lo.y())) + 5);
  cv::Subdiv2D subdiv(rect);
  for (const Vertex& v : vertices) {
    subdiv.insert(cv::Point2f(static_cast<float>(v.px.x()), static_cast<float>(v.px.y())));
  }
  std::vector<cv::Vec6f> list;
  subdiv.getTriangleList(list);

  const std::vector<GrownHull> hulls = GrowHulls(input.moving_hulls_xy, f, options.hull_margin_px);
  auto in_hull = [&](const Eigen::Vector2d& p) {
    for (const GrownHull& h : hulls) {
      if (h.Contains(p)) return true;
    }
    return false;
  };
  const double cos_max_incidence = std::cos(options.max_incidence_deg * M_PI / 180.0);

  std::vector<Triangle> kept;
  for (const cv::Vec6f& t : list) {
    int id[3];
    bool known = true;
    for (int k = 0; k < 3; ++k) {
      auto it = vertex_of.find(CoordKey(t[2 * k], t[2 * k + 1]));
      if (it == vertex_of.end()) {
        known = false;  // a virtual vertex of the subdivision's bounding triangle
        break;
      }
      id[k] = it->second;
    }
    if (!known) continue;
    ++st.triangles;
    const Vertex& a = vertices[static_cast<size_t>(id[0])];
    const Vertex& b = vertices[static_cast<size_t>(id[1])];
    const Vertex& c = vertices[static_cast<size_t>(id[2])];
    Triangle tri{id[0], id[1], id[2], 0.0, 0.0};
    tri.longest_px = std::max({(a.px - b.px).norm(), (b.px - c.px).norm(), (c.px - a.px).norm()});
    if (tri.longest_px > options.max_edge_px) {
      ++st.rejected_edge;
      continue;
    }
    const double inv_min = std::min({a.inv_depth, b.inv_depth, c.inv_depth});
    const double inv_max = std::max({a.inv_depth, b.inv_depth, c.inv_depth});
    if (inv_max > options.max_depth_ratio * inv_min) {
      ++st.rejected_depth;
      continue;
    }
    tri.max_depth = 1.0 / inv_min;
    const Eigen::Vector3d normal = (b.in_cam - a.in_cam).cross(c.in_cam - a.in_cam);
    const Eigen::Vector3d view = (a.in_cam + b.in_cam + c.in_cam) / 3.0;
    const double nn = normal.norm() * view.norm();
    if (!(nn > 0.0) || std::abs(normal.dot(view)) < cos_max_incidence * nn) {
      ++st.rejected_incidence;
      continue;
    }
    if (!hulls.empty()) {
      const Eigen::Vector2d centroid = (a.px + b.px + c.px) / 3.0;
      bool touches = in_hull(a.px) || in_hull(b.px) || in_hull(c.px) || in_hull(centroid);
      for (size_t h = 0; h < hulls.size() && !touches; ++h) {
        for (const Eigen::Vector2f& q : hulls[h].points) {
          if (InTriangle(q.cast<double>(), a.px, b.px, c.px)) {
            touches = true;
            break;
          }
        }
      }
      if (touches) {
        ++st.rejected_moving;
        continue;
      }
    }
    kept.push_back(tri);
  }
  st.triangles_used = static_cast<int>(kept.size());
  if (kept.empty()) return samples;

  // Subdivisions per triangle edge for a spacing scale; samples it gives (corners are
  // the points themselves, not samples).
  auto subdivisions = [&](const Triangle& t, double scale) {
    const double spacing =
        scale * std::max(options.min_spacing_px, options.sample_spacing_voxels * input.voxel * f / t.max_depth);
    return std::max(1, static_cast<int>(std::ceil(t.longest_px / spacing - 1e-9)));
  };
  auto count = [&](double scale) {
    int64_t total = 0;
    for (const Triangle& t : kept) {
      const int64_t n = subdivisions(t, scale);
      total += (n + 1) * (n + 2) / 2 - 3;
    }
    return total;
  };
  double scale = 1.0;
  int64_t total = count(scale);
  for (int iter = 0; iter < 20 && total > options.max_samples; ++iter) {
    scale *= std::max(1.05, std::sqrt(static_cast<double>(total) / std::max(1, options.max_samples)));
    total = count(scale);
  }
  st.spacing_scale = scale;
  if (total > options.max_samples) return samples;  // max_samples = 0, or not reachable

  const Rigid3d world_from_cam = input.cam_from_world.Inverse();
  samples.reserve(static_cast<size_t>(total));
  for (const Triangle& t : kept) {
    const Vertex& a = vertices[static_cast<size_t>(t.a)];
    const Vertex& b = vertices[static_cast<size_t>(t.b)];
    const Vertex& c = vertices[static_cast<size_t>(t.c)];
    const int n = subdivisions(t, scale);
    const double inv_n = 1.0 / n;
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const int k = n - i - j;
        if (i == n || j == n || k == n) continue;  // a corner
        const double wa = i * inv_n, wb = j * inv_n, wc = k * inv_n;
        const Eigen::Vector2d px = wa * a.px + wb * b.px + wc * c.px;
        if (!hulls.empty() && in_hull(px)) {
          ++st.samples_in_hulls;
          continue;
        }
        const double inv_depth = wa * a.inv_depth + wb * b.inv_depth + wc * c.inv_depth;
        const double z = 1.0 / inv_depth;
        const Eigen::Vector3d in_cam(px.x() / f * z, px.y() / f * z, z);
        samples.push_back(world_from_cam * in_cam);
      }
    }
  }
  st.samples = static_cast<int>(samples.size());
  return samples;
}

}  // namespace mbslam
