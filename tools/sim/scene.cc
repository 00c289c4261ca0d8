#include "tools/sim/scene.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <random>
#include <thread>

namespace mbslam {
namespace sim {

const char* BodyClassName(BodyClass c) {
  switch (c) {
    case BodyClass::kStatic:
      return "static";
    case BodyClass::kCar:
      return "car";
    case BodyClass::kPerson:
      return "person";
    case BodyClass::kBox:
      return "box";
    case BodyClass::kRobot:
      return "robot";
  }
  return "unknown";
}

int Scene::BodyIndex(int id) const {
  for (size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].id == id) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

Eigen::AlignedBox3d Scene::BodyBounds(size_t index) const {
  Eigen::AlignedBox3d box;
  for (const Quad& q : bodies[index].quads) {
    box.extend(q.origin);
    box.extend(q.origin + q.edge_u);
    box.extend(q.origin + q.edge_v);
    box.extend(q.origin + q.edge_u + q.edge_v);
  }
  return box;
}

SceneBuilder::SceneBuilder(Scene* scene, std::vector<Eigen::Vector3d> camera_positions,
                           double base_texel_m, double lod_distance_m, int max_texture_px,
                           uint64_t seed)
    : scene_(scene),
      camera_positions_(std::move(camera_positions)),
      base_texel_m_(base_texel_m),
      lod_distance_m_(lod_distance_m),
      max_texture_px_(max_texture_px),
      seed_(seed) {}

uint64_t SceneBuilder::NextSeed() {
  seed_ = seed_ * 6364136223846793005ULL + 1442695040888963407ULL;
  return seed_ >> 11;
}

double SceneBuilder::DistanceToCamera(const Eigen::Vector3d& point) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& c : camera_positions_) {
    best = std::min(best, (c - point).norm());
  }
  return best;
}

int SceneBuilder::AddTexture(const Quad& quad, const Rigid3d& world_from_body, bool is_static,
                             TextureStyle style, const cv::Scalar& tint, double texel_factor) {
  double lod = 1.0;
  if (is_static) {
    // Closest distance of the quad to the camera path, from a few samples on the quad,
    // and whether the camera ever sees its front side.
    double distance = std::numeric_limits<double>::infinity();
    bool front_seen = false;
    const Eigen::Vector3d n = world_from_body.rotation * quad.Normal();
    for (double s : {0.0, 0.25, 0.5, 0.75, 1.0}) {
      for (double t : {0.0, 0.25, 0.5, 0.75, 1.0}) {
        const Eigen::Vector3d p = world_from_body * quad.Point(s, t);
        distance = std::min(distance, DistanceToCamera(p));
        for (const auto& c : camera_positions_) {
          front_seen = front_seen || n.dot(c - p) > 0.0;
        }
      }
    }
    if (!front_seen) {  // a token texture: it is never drawn into any image
      sample_weight_ = 0.0;
      jobs_.push_back({style, 16, 16, 1.0, NextSeed(), tint});
      scene_->textures.emplace_back();
      return static_cast<int>(scene_->textures.size()) - 1;
    }
    lod = std::max(1.0, distance / lod_distance_m_);
    sample_weight_ = 1.0 / (lod * lod);
  } else {
    sample_weight_ = 1.0;
  }
  const double texel = base_texel_m_ * texel_factor * lod;
  const double len_u = quad.edge_u.norm();
  const double len_v = quad.edge_v.norm();
  const int w = std::clamp(static_cast<int>(std::ceil(len_u / texel)), 16, max_texture_px_);
  const int h = std::clamp(static_cast<int>(std::ceil(len_v / texel)), 16, max_texture_px_);
  const double effective_texel = std::max(len_u / w, len_v / h);
  jobs_.push_back({style, w, h, effective_texel, NextSeed(), tint});
  scene_->textures.emplace_back();
  return static_cast<int>(scene_->textures.size()) - 1;
}

void SceneBuilder::GenerateTextures(int threads) {
  // Every texture depends only on its own job (seed included): the result is the same
  // for any number of threads.
  const size_t first = scene_->textures.size() - jobs_.size();
  std::atomic<size_t> next{0};
  auto work = [&]() {
    for (size_t i = next++; i < jobs_.size(); i = next++) {
      const TextureJob& j = jobs_[i];
      scene_->textures[first + i] =
          MakeTexture(j.style, j.width, j.height, j.texel_m, j.seed, j.tint);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::max(1, threads); ++t) {
    pool.emplace_back(work);
  }
  work();
  for (auto& t : pool) {
    t.join();
  }
  jobs_.clear();
}

void SceneBuilder::AddBox(SceneBody* body, const Rigid3d& world_from_body,
                          const Eigen::Vector3d& center_in_body, const Eigen::Vector3d& size,
                          double yaw, TextureStyle style, bool with_bottom, const cv::Scalar& tint,
                          double texel_factor) {
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d h = 0.5 * size;
  const double a = h.x(), b = h.y(), c = h.z();
  // Faces in the box frame: origin, edge_u, edge_v with edge_u x edge_v pointing out.
  struct Face {
    Eigen::Vector3d o, u, v;
  };
  std::vector<Face> faces = {
      {{a, -b, -c}, {0, 2 * b, 0}, {0, 0, 2 * c}},   // +x
      {{-a, b, -c}, {0, -2 * b, 0}, {0, 0, 2 * c}},  // -x
      {{a, b, -c}, {-2 * a, 0, 0}, {0, 0, 2 * c}},   // +y
      {{-a, -b, -c}, {2 * a, 0, 0}, {0, 0, 2 * c}},  // -y
      {{-a, -b, c}, {2 * a, 0, 0}, {0, 2 * b, 0}},   // +z
  };
  if (with_bottom) {
    faces.push_back({{-a, b, -c}, {2 * a, 0, 0}, {0, -2 * b, 0}});  // -z
  }
  for (const Face& f : faces) {
    Quad q;
    q.origin = center_in_body + R * f.o;
    q.edge_u = R * f.u;
    q.edge_v = R * f.v;
    q.texture = AddTexture(q, world_from_body, body->id == 0, style, tint, texel_factor);
    q.sample_weight = sample_weight_;
    body->quads.push_back(q);
  }
}

void SceneBuilder::AddGroundTile(SceneBody* body, double x0, double y0, double x1, double y1,
                                 TextureStyle style) {
  Quad q;
  q.origin = Eigen::Vector3d(x0, y0, 0.0);
  q.edge_u = Eigen::Vector3d(x1 - x0, 0.0, 0.0);
  q.edge_v = Eigen::Vector3d(0.0, y1 - y0, 0.0);
  q.texture = AddTexture(q, Rigid3d(), true, style, cv::Scalar(-1, -1, -1), 1.0);
  q.sample_weight = sample_weight_;
  body->quads.push_back(q);
}

namespace {

// Ray / parallelogram intersection (front side only). Returns false on a miss.
bool IntersectQuad(const Quad& q, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double* t,
                   double* s_out, double* t_out) {
  const Eigen::Vector3d n = q.edge_u.cross(q.edge_v);
  const double denom = n.dot(d);
  if (denom >= 0.0) {
    return false;  // parallel or seen from behind
  }
  const double dist = n.dot(q.origin - o) / denom;
  if (dist <= 0.0) {
    return false;
  }
  const Eigen::Vector3d p = o + dist * d - q.origin;
  // Solve p = s u + t v in the least-squares sense (exact for points in the plane).
  const double uu = q.edge_u.dot(q.edge_u), uv = q.edge_u.dot(q.edge_v),
               vv = q.edge_v.dot(q.edge_v);
  const double pu = p.dot(q.edge_u), pv = p.dot(q.edge_v);
  const double det = uu * vv - uv * uv;
  const double s = (pu * vv - pv * uv) / det;
  const double tt = (pv * uu - pu * uv) / det;
  if (s < 0.0 || s > 1.0 || tt < 0.0 || tt > 1.0) {
    return false;
  }
  *t = dist;
  *s_out = s;
  *t_out = tt;
  return true;
}

bool RayHitsBox(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& o,
                const Eigen::Vector3d& d) {
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 3; ++i) {
    const double lo = box.min()[i] - 1e-9, hi = box.max()[i] + 1e-9;
    if (std::abs(d[i]) < 1e-15) {
      if (o[i] < lo || o[i] > hi) {
        return false;
      }
      continue;
    }
    double a = (lo - o[i]) / d[i], b = (hi - o[i]) / d[i];
    if (a > b) {
      std::swap(a, b);
    }
    t0 = std::max(t0, a);
    t1 = std::min(t1, b);
    if (t0 > t1) {
      return false;
    }
  }
  return true;
}

}  // namespace

RayCaster::RayCaster(const Scene& scene) : scene_(scene) {
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    bounds_.push_back(scene.BodyBounds(b));
  }
}

RayHit RayCaster::Cast(const std::vector<Rigid3d>& world_from_body, const Eigen::Vector3d& origin,
                       const Eigen::Vector3d& direction) const {
  const Scene& scene = scene_;
  RayHit best;
  best.distance = std::numeric_limits<double>::infinity();
  for (size_t b = 0; b < scene.bodies.size(); ++b) {
    const Rigid3d body_from_world = world_from_body[b].Inverse();
    const Eigen::Vector3d o = body_from_world * origin;
    const Eigen::Vector3d d = body_from_world.rotation * direction;
    if (!RayHitsBox(bounds_[b], o, d)) {
      continue;
    }
    const auto& quads = scene.bodies[b].quads;
    for (size_t k = 0; k < quads.size(); ++k) {
      double t, s, tt;
      if (!IntersectQuad(quads[k], o, d, &t, &s, &tt) || t >= best.distance) {
        continue;
      }
      best.body_index = static_cast<int>(b);
      best.quad_index = static_cast<int>(k);
      best.distance = t;
      best.point_in_body = o + t * d;
      const double lu = quads[k].edge_u.norm(), lv = quads[k].edge_v.norm();
      best.edge_distance = std::min({s * lu, (1.0 - s) * lu, tt * lv, (1.0 - tt) * lv});
    }
  }
  if (best.body_index < 0) {
    best.distance = 0.0;
  }
  return best;
}

std::vector<Eigen::Vector3d> SampleSurfacePoints(const SceneBody& body, double points_per_m2,
                                                 int min_points, int max_points, uint64_t seed) {
  std::vector<double> cumulative;
  double total = 0.0;
  for (const Quad& q : body.quads) {
    total += q.Area() * std::max(0.0, q.sample_weight);
    cumulative.push_back(total);
  }
  std::vector<Eigen::Vector3d> points;
  if (body.quads.empty() || total <= 0.0) {
    return points;
  }
  const int n =
      std::clamp(static_cast<int>(std::lround(points_per_m2 * total)), min_points, max_points);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  points.reserve(static_cast<size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double r = u(rng) * total;
    const size_t k =
        std::min(static_cast<size_t>(std::upper_bound(cumulative.begin(), cumulative.end(), r) -
                                     cumulative.begin()),
                 body.quads.size() - 1);
    points.push_back(body.quads[k].Point(u(rng), u(rng)));
  }
  return points;
}

}  // namespace sim
}  // namespace mbslam
