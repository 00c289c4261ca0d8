#include "viewer/view3d_renderer.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "common/util/logging.h"
#include "common/util/time.h"
#include "viewer/colors.h"
#include "viewer/draw_util.h"
#include "viewer/offscreen_gl.h"

namespace mbslam {
namespace viewer {
namespace {

// Points and lines: position and colour.
const char* kFlatVertexShader = R"(#version 330
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec4 a_color;
uniform mat4 u_clip_from_world;
uniform float u_point_size;
out vec4 v_color;
void main() {
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
  gl_PointSize = u_point_size;
  v_color = a_color;
}
)";

const char* kFlatFragmentShader = R"(#version 330
in vec4 v_color;
uniform int u_round_points;
out vec4 o_color;
void main() {
  if (u_round_points != 0) {
    vec2 d = gl_PointCoord - vec2(0.5);
    if (dot(d, d) > 0.25) discard;
  }
  o_color = v_color;
}
)";

// Shaded triangles (predicted volumes): world normal, Lambert with an ambient floor.
const char* kShadedVertexShader = R"(#version 330
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_color;
uniform mat4 u_clip_from_world;
out vec3 v_normal;
out vec4 v_color;
void main() {
  gl_Position = u_clip_from_world * vec4(a_position, 1.0);
  v_normal = a_normal;
  v_color = a_color;
}
)";

// Instanced axis-aligned cubes (voxels): a unit cube scaled and moved per instance.
const char* kCubeVertexShader = R"(#version 330
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_center_size;
layout(location = 3) in vec4 a_color;
uniform mat4 u_clip_from_world;
out vec3 v_normal;
out vec4 v_color;
void main() {
  vec3 p = a_center_size.xyz + a_center_size.w * a_position;
  gl_Position = u_clip_from_world * vec4(p, 1.0);
  v_normal = a_normal;
  v_color = a_color;
}
)";

const char* kShadedFragmentShader = R"(#version 330
in vec3 v_normal;
in vec4 v_color;
uniform vec3 u_light;
out vec4 o_color;
void main() {
  float lambert = max(dot(normalize(v_normal), u_light), 0.0);
  o_color = vec4(v_color.rgb * (0.55 + 0.45 * lambert), v_color.a);
}
)";

struct ColorVertex {
  float position[3];
  uint8_t color[4];
};
struct ShadedVertex {
  float position[3];
  float normal[3];
  uint8_t color[4];
};
struct CubeInstance {
  float center_size[4];
  uint8_t color[4];
};

ColorVertex MakeVertex(const Eigen::Vector3d& p, const Rgb& c, double alpha = 1.0) {
  ColorVertex v;
  v.position[0] = static_cast<float>(p.x());
  v.position[1] = static_cast<float>(p.y());
  v.position[2] = static_cast<float>(p.z());
  v.color[0] = c.r;
  v.color[1] = c.g;
  v.color[2] = c.b;
  v.color[3] = static_cast<uint8_t>(std::lround(std::clamp(alpha, 0.0, 1.0) * 255.0));
  return v;
}

void AddLine(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Rgb& c,
             std::vector<ColorVertex>* lines) {
  if (!a.allFinite() || !b.allFinite()) return;
  lines->push_back(MakeVertex(a, c));
  lines->push_back(MakeVertex(b, c));
}

void AddPolyline(const std::vector<Eigen::Vector3d>& points, const Rgb& c,
                 std::vector<ColorVertex>* lines) {
  for (size_t i = 1; i < points.size(); ++i) AddLine(points[i - 1], points[i], c, lines);
}

// A camera frustum: apex at the centre, image rectangle at `depth` ahead.
void AddFrustum(const Pose& world_from_cam, double depth, double aspect, const Rgb& c,
                std::vector<ColorVertex>* lines) {
  const Eigen::Quaterniond q = world_from_cam.orientation.normalized();
  const Eigen::Vector3d apex = world_from_cam.position;
  const double half_h = 0.4 * depth, half_w = half_h * aspect;
  std::array<Eigen::Vector3d, 4> corners;
  const double sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
  for (int i = 0; i < 4; ++i) {
    corners[i] = apex + q * Eigen::Vector3d(sx[i] * half_w, sy[i] * half_h, depth);
  }
  for (int i = 0; i < 4; ++i) {
    AddLine(apex, corners[i], c, lines);
    AddLine(corners[i], corners[(i + 1) % 4], c, lines);
  }
  // A tick on the top edge shows which way is up in the image.
  const Eigen::Vector3d top_mid = 0.5 * (corners[0] + corners[1]);
  AddLine(top_mid, top_mid + q * Eigen::Vector3d(0, -0.5 * half_h, 0), c, lines);
}

std::array<Eigen::Vector3d, 8> BoxCorners(const OrientedBox& box) {
  std::array<Eigen::Vector3d, 8> corners;
  Eigen::Quaterniond q = box.world_from_box;
  q = q.norm() > 1e-9 ? q.normalized() : Eigen::Quaterniond::Identity();
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d s((i & 1) ? 1.0 : -1.0, (i & 2) ? 1.0 : -1.0, (i & 4) ? 1.0 : -1.0);
    corners[i] = box.center + q * s.cwiseProduct(box.half_extent.cwiseAbs());
  }
  return corners;
}

void AddBoxEdges(const OrientedBox& box, const Rgb& c, std::vector<ColorVertex>* lines) {
  const auto k = BoxCorners(box);
  for (int i = 0; i < 8; ++i) {
    for (int bit : {1, 2, 4}) {
      if (!(i & bit)) AddLine(k[i], k[i | bit], c, lines);
    }
  }
}

// The faces of a box (or of the unit cube) as triangles, counter-clockwise seen from
// outside, with outward normals.
template <typename Emit>
void ForEachBoxTriangle(const std::array<Eigen::Vector3d, 8>& k, Emit emit) {
  // Faces as corner indices (bit 0 = +x, bit 1 = +y, bit 2 = +z), ordered so that
  // (c1 - c0) x (c3 - c0) points outward.
  static const int kFaces[6][4] = {
      {1, 3, 7, 5},  // +x
      {0, 4, 6, 2},  // -x
      {2, 6, 7, 3},  // +y
      {0, 1, 5, 4},  // -y
      {4, 5, 7, 6},  // +z
      {0, 2, 3, 1},  // -z
  };
  for (const auto& f : kFaces) {
    Eigen::Vector3d n = (k[f[1]] - k[f[0]]).cross(k[f[3]] - k[f[0]]);
    n = n.norm() > 1e-20 ? n.normalized() : Eigen::Vector3d::UnitZ();
    emit(k[f[0]], k[f[1]], k[f[2]], n);
    emit(k[f[0]], k[f[2]], k[f[3]], n);
  }
}

// 1, 2 or 5 times a power of ten, close to `x`.
double NiceStep(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  const double m = x / p;
  return (m < 1.5 ? 1.0 : m < 3.5 ? 2.0 : m < 7.5 ? 5.0 : 10.0) * p;
}

struct Geometry {
  std::vector<ColorVertex> static_points, object_points, particles;
  std::vector<ColorVertex> grid_lines, frustum_lines, trajectory_lines, current_camera_lines,
      box_lines;
  std::vector<ShadedVertex> volume_triangles;
  std::vector<CubeInstance> voxels;
};

std::string FormatSeconds(int64_t utime) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.3f s", UtimeToSeconds(utime));
  return buf;
}

}  // namespace

HeightScale ComputeHeightScale(const View3dOptions& options, const MapData& map) {
  HeightScale scale;
  if (map.ground_plane) {
    const Eigen::Vector3d n = map.ground_plane->head<3>();
    if (n.allFinite() && n.norm() > 0.5 && std::isfinite((*map.ground_plane)[3])) {
      scale.normal = n.normalized();
      scale.offset = (*map.ground_plane)[3] / n.norm();
    }
  }
  if (options.height_range[0] < options.height_range[1]) {
    scale.low = options.height_range[0];
    scale.high = options.height_range[1];
    return scale;
  }
  std::vector<double> heights;
  heights.reserve(map.points.size());
  for (const auto& p : map.points) {
    if (p.allFinite()) heights.push_back(scale.Height(p.cast<double>()));
  }
  if (heights.size() >= 2) {
    const size_t lo = heights.size() / 20, hi = heights.size() - 1 - heights.size() / 20;
    std::nth_element(heights.begin(), heights.begin() + static_cast<long>(lo), heights.end());
    scale.low = heights[lo];
    std::nth_element(heights.begin(), heights.begin() + static_cast<long>(hi), heights.end());
    scale.high = heights[hi];
    // With a ground plane, the ground itself is the bottom of the scale.
    if (map.ground_plane) scale.low = std::max(scale.low, 0.0);
  }
  if (!(scale.high - scale.low > 1e-9)) scale.high = scale.low + 1.0;
  return scale;
}

struct View3dRenderer::Impl {
  View3dOptions options;
  std::unique_ptr<OffscreenGl> gl;
  struct Program {
    GLuint id = 0;
    GLint clip_from_world = -1, point_size = -1, round_points = -1, light = -1;
  };
  Program flat, shaded, cube;
  GLuint flat_vao = 0, flat_vbo = 0;
  GLuint shaded_vao = 0, shaded_vbo = 0;
  GLuint cube_vao = 0, cube_mesh_vbo = 0, cube_instance_vbo = 0;
  std::vector<GLuint> shaders;

  ~Impl() {
    if (!gl || !gl->MakeCurrent()) return;
    const GLuint buffers[] = {flat_vbo, shaded_vbo, cube_mesh_vbo, cube_instance_vbo};
    glDeleteBuffers(4, buffers);
    const GLuint vaos[] = {flat_vao, shaded_vao, cube_vao};
    glDeleteVertexArrays(3, vaos);
    for (const Program* p : {&flat, &shaded, &cube}) glDeleteProgram(p->id);
    for (GLuint s : shaders) glDeleteShader(s);
  }

  Status Compile(GLenum type, const char* source, GLuint* shader) {
    *shader = glCreateShader(type);
    shaders.push_back(*shader);
    glShaderSource(*shader, 1, &source, nullptr);
    glCompileShader(*shader);
    GLint ok = 0;
    glGetShaderiv(*shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[2048] = {0};
      glGetShaderInfoLog(*shader, sizeof(log), nullptr, log);
      return Status::Error(std::string("viewer shader does not compile: ") + log);
    }
    return Status::Ok();
  }

  Status Link(const char* vertex_source, const char* fragment_source, Program* p) {
    GLuint vs = 0, fs = 0;
    MBSLAM_RETURN_IF_ERROR(Compile(GL_VERTEX_SHADER, vertex_source, &vs));
    MBSLAM_RETURN_IF_ERROR(Compile(GL_FRAGMENT_SHADER, fragment_source, &fs));
    p->id = glCreateProgram();
    glAttachShader(p->id, vs);
    glAttachShader(p->id, fs);
    glLinkProgram(p->id);
    GLint linked = 0;
    glGetProgramiv(p->id, GL_LINK_STATUS, &linked);
    if (!linked) {
      char log[2048] = {0};
      glGetProgramInfoLog(p->id, sizeof(log), nullptr, log);
      return Status::Error(std::string("viewer shaders do not link: ") + log);
    }
    p->clip_from_world = glGetUniformLocation(p->id, "u_clip_from_world");
    p->point_size = glGetUniformLocation(p->id, "u_point_size");
    p->round_points = glGetUniformLocation(p->id, "u_round_points");
    p->light = glGetUniformLocation(p->id, "u_light");
    return Status::Ok();
  }

  Status Init() {
    Status s;
    gl = OffscreenGl::Create(options.width, options.height, options.antialias_samples, &s);
    if (!gl) return s;
    MBSLAM_RETURN_IF_ERROR(Link(kFlatVertexShader, kFlatFragmentShader, &flat));
    MBSLAM_RETURN_IF_ERROR(Link(kShadedVertexShader, kShadedFragmentShader, &shaded));
    MBSLAM_RETURN_IF_ERROR(Link(kCubeVertexShader, kShadedFragmentShader, &cube));

    glGenVertexArrays(1, &flat_vao);
    glBindVertexArray(flat_vao);
    glGenBuffers(1, &flat_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, flat_vbo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(ColorVertex),
                          reinterpret_cast<void*>(offsetof(ColorVertex, position)));
    glVertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(ColorVertex),
                          reinterpret_cast<void*>(offsetof(ColorVertex, color)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);

    glGenVertexArrays(1, &shaded_vao);
    glBindVertexArray(shaded_vao);
    glGenBuffers(1, &shaded_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, shaded_vbo);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(ShadedVertex),
                          reinterpret_cast<void*>(offsetof(ShadedVertex, position)));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(ShadedVertex),
                          reinterpret_cast<void*>(offsetof(ShadedVertex, normal)));
    glVertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(ShadedVertex),
                          reinterpret_cast<void*>(offsetof(ShadedVertex, color)));
    for (GLuint i = 0; i < 3; ++i) glEnableVertexAttribArray(i);

    // Unit cube [-0.5, 0.5]^3 (position + normal) and the per-voxel instance buffer.
    std::array<Eigen::Vector3d, 8> unit;
    for (int i = 0; i < 8; ++i) {
      unit[i] = Eigen::Vector3d((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
    }
    std::vector<float> mesh;
    ForEachBoxTriangle(unit, [&mesh](const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                     const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
      for (const Eigen::Vector3d* p : {&a, &b, &c}) {
        mesh.insert(mesh.end(), {static_cast<float>(p->x()), static_cast<float>(p->y()),
                                 static_cast<float>(p->z()), static_cast<float>(n.x()),
                                 static_cast<float>(n.y()), static_cast<float>(n.z())});
      }
    });
    glGenVertexArrays(1, &cube_vao);
    glBindVertexArray(cube_vao);
    glGenBuffers(1, &cube_mesh_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, cube_mesh_vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(mesh.size() * sizeof(float)), mesh.data(),
                 GL_STATIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), reinterpret_cast<void*>(0));
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float),
                          reinterpret_cast<void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glGenBuffers(1, &cube_instance_vbo);
    glBindBuffer(GL_ARRAY_BUFFER, cube_instance_vbo);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, sizeof(CubeInstance),
                          reinterpret_cast<void*>(offsetof(CubeInstance, center_size)));
    glVertexAttribPointer(3, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(CubeInstance),
                          reinterpret_cast<void*>(offsetof(CubeInstance, color)));
    glEnableVertexAttribArray(2);
    glEnableVertexAttribArray(3);
    glVertexAttribDivisor(2, 1);
    glVertexAttribDivisor(3, 1);
    glBindVertexArray(0);

    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
      return Status::Error("viewer GL set-up failed with error " + std::to_string(err));
    }
    return Status::Ok();
  }

  Geometry Build(const SceneState& scene, const HeightScale& heights, double scene_scale) const {
    Geometry g;
    const MapData& map = scene.map();
    const double aspect = scene.image_width() > 0 && scene.image_height() > 0
                              ? static_cast<double>(scene.image_width()) / scene.image_height()
                              : 4.0 / 3.0;
    const double frustum = options.frustum_size > 0.0 ? options.frustum_size : 0.02 * scene_scale;

    if (options.show_map_points) {
      const bool rgb =
          options.static_point_color == "rgb" && map.colors.size() == map.points.size();
      g.static_points.reserve(map.points.size());
      for (size_t i = 0; i < map.points.size(); ++i) {
        const Eigen::Vector3d p = map.points[i].cast<double>();
        if (!p.allFinite()) continue;
        const Rgb c = rgb ? Rgb{map.colors[i][0], map.colors[i][1], map.colors[i][2]}
                          : HeightColor(heights.Normalized(p));
        g.static_points.push_back(MakeVertex(p, c));
      }
    }
    if (options.show_ground_grid && map.ground_plane) {
      const Eigen::Vector3d n = heights.normal;
      const Eigen::Vector3d e1 = Horizontal(Eigen::Vector3d::UnitZ(), n);
      const Eigen::Vector3d e2 = n.cross(e1);
      const Eigen::AlignedBox3d bounds = SceneBounds(scene, options.framing_percentile);
      const Eigen::Vector3d c = bounds.center() - heights.Height(bounds.center()) * n;
      const double radius = 0.6 * bounds.diagonal().norm();
      const double step = NiceStep(radius / 6.0);
      const int k = std::min(200, static_cast<int>(std::ceil(radius / step)));
      const Eigen::Vector3d origin =
          c - e1 * std::fmod(e1.dot(c), step) - e2 * std::fmod(e2.dot(c), step);
      for (int i = -k; i <= k; ++i) {
        AddLine(origin + e1 * (i * step) - e2 * (k * step),
                origin + e1 * (i * step) + e2 * (k * step), kGridColor, &g.grid_lines);
        AddLine(origin + e2 * (i * step) - e1 * (k * step),
                origin + e2 * (i * step) + e1 * (k * step), kGridColor, &g.grid_lines);
      }
    }
    if (options.show_keyframes) {
      for (const KeyframeData& kf : map.keyframes) {
        AddFrustum(kf.world_from_cam, frustum, aspect, kKeyframeColor, &g.frustum_lines);
      }
    }
    if (options.show_trajectory) {
      const auto& trajectory = scene.camera_trajectory();
      for (size_t i = 1; i < trajectory.size(); ++i) {
        AddLine(trajectory[i - 1].world_from_cam.position, trajectory[i].world_from_cam.position,
                kCameraTrajectoryColor, &g.trajectory_lines);
      }
      const auto& current = scene.current_camera();
      if (current && HasPose(current->tracking_state)) {
        AddFrustum(current->world_from_cam, 2.5 * frustum, aspect, kCurrentCameraColor,
                   &g.current_camera_lines);
      }
    }
    const ObjectsData& objects = scene.objects();
    if (options.show_objects) {
      for (const auto& [id, trajectory] : scene.object_trajectories()) {
        AddPolyline(trajectory, ObjectColor(id), &g.trajectory_lines);
      }
    }
    for (const ObjectData& o : objects.objects) {
      const Rgb color = ObjectColor(o.id);
      if (options.show_objects) {
        for (const auto& p : o.points) {
          if (p.allFinite()) g.object_points.push_back(MakeVertex(p.cast<double>(), color));
        }
      }
      if (options.show_particles) {
        for (const auto& p : o.particles) {
          if (p.allFinite()) g.particles.push_back(MakeVertex(p.cast<double>(), kParticleColor));
        }
      }
      if (options.show_volumes && !o.volumes.empty()) {
        const int64_t max_horizon = std::max<int64_t>(o.volumes.back().horizon_us, 1);
        for (size_t i = 0; i < o.volumes.size(); ++i) {
          const OrientedBox& box = o.volumes[i];
          if (!box.center.allFinite() || !box.half_extent.allFinite() ||
              !box.world_from_box.coeffs().allFinite()) {
            continue;
          }
          if (i == 0) AddBoxEdges(box, color, &g.box_lines);
          const double fade = 1.0 - 0.6 * std::clamp(static_cast<double>(box.horizon_us) /
                                                         static_cast<double>(max_horizon),
                                                     0.0, 1.0);
          const uint8_t alpha =
              static_cast<uint8_t>(std::lround(255.0 * options.volume_alpha * fade));
          ForEachBoxTriangle(BoxCorners(box),
                             [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                 const Eigen::Vector3d& c, const Eigen::Vector3d& n) {
                               for (const Eigen::Vector3d* p : {&a, &b, &c}) {
                                 ShadedVertex v;
                                 for (int k = 0; k < 3; ++k) {
                                   v.position[k] = static_cast<float>((*p)[k]);
                                   v.normal[k] = static_cast<float>(n[k]);
                                 }
                                 v.color[0] = color.r;
                                 v.color[1] = color.g;
                                 v.color[2] = color.b;
                                 v.color[3] = alpha;
                                 g.volume_triangles.push_back(v);
                               }
                             });
        }
      }
    }
    if (options.show_voxels) {
      const OccupancyData& occupancy = scene.occupancy();
      g.voxels.reserve(occupancy.voxels.size());
      const uint8_t alpha = static_cast<uint8_t>(std::lround(255.0 * options.voxel_alpha));
      for (const Voxel& v : occupancy.voxels) {
        if (!v.center.allFinite() || !(v.size > 0.0f)) continue;
        const Rgb c = HeightColor(heights.Normalized(v.center.cast<double>()));
        CubeInstance instance;
        instance.center_size[0] = v.center.x();
        instance.center_size[1] = v.center.y();
        instance.center_size[2] = v.center.z();
        instance.center_size[3] = v.size;
        instance.color[0] = c.r;
        instance.color[1] = c.g;
        instance.color[2] = c.b;
        instance.color[3] = alpha;
        g.voxels.push_back(instance);
      }
    }
    return g;
  }

  void DrawFlat(const std::vector<ColorVertex>& vertices, GLenum mode, float size, bool round) {
    if (vertices.empty()) return;
    glBindVertexArray(flat_vao);
    glBindBuffer(GL_ARRAY_BUFFER, flat_vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(ColorVertex)),
                 vertices.data(), GL_STREAM_DRAW);
    glUniform1f(flat.point_size, size);
    glUniform1i(flat.round_points, round ? 1 : 0);
    if (mode == GL_LINES) glLineWidth(size);
    glDrawArrays(mode, 0, static_cast<GLsizei>(vertices.size()));
  }

  Status Draw(const Geometry& g, const ViewCamera& camera, const Eigen::Vector3d& light) {
    gl->BindTarget();
    const GLfloat background[4] = {static_cast<GLfloat>(options.background_rgb[0]),
                                   static_cast<GLfloat>(options.background_rgb[1]),
                                   static_cast<GLfloat>(options.background_rgb[2]), 1.0f};
    glClearBufferfv(GL_COLOR, 0, background);
    const GLfloat far_depth = 1.0f;
    glClearBufferfv(GL_DEPTH, 0, &far_depth);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glEnable(GL_PROGRAM_POINT_SIZE);
    glEnable(0x8861);  // GL_POINT_SPRITE: gl_PointCoord in a compatibility context
    glEnable(GL_MULTISAMPLE);

    const Eigen::Matrix4f clip_from_world = camera.ClipFromWorld().cast<float>();
    const Eigen::Vector3f light_f = light.cast<float>();

    // Opaque: grid, points, lines.
    glUseProgram(flat.id);
    glUniformMatrix4fv(flat.clip_from_world, 1, GL_FALSE, clip_from_world.data());
    const float p = static_cast<float>(options.point_size_px);
    const float w = static_cast<float>(options.trajectory_width_px);
    DrawFlat(g.grid_lines, GL_LINES, 1.0f, false);
    DrawFlat(g.static_points, GL_POINTS, p, true);
    DrawFlat(g.frustum_lines, GL_LINES, std::max(1.0f, 0.5f * w), false);
    DrawFlat(g.trajectory_lines, GL_LINES, w, false);
    DrawFlat(g.current_camera_lines, GL_LINES, std::max(1.0f, 0.8f * w), false);
    DrawFlat(g.box_lines, GL_LINES, std::max(1.0f, 0.5f * w), false);
    DrawFlat(g.object_points, GL_POINTS, 1.5f * p, true);
    DrawFlat(g.particles, GL_POINTS, std::max(3.0f, p), true);

    // Transparent: voxels, then volumes; front faces only, no depth writes.
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glDepthMask(GL_FALSE);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    if (!g.voxels.empty()) {
      glUseProgram(cube.id);
      glUniformMatrix4fv(cube.clip_from_world, 1, GL_FALSE, clip_from_world.data());
      glUniform3fv(cube.light, 1, light_f.data());
      glBindVertexArray(cube_vao);
      glBindBuffer(GL_ARRAY_BUFFER, cube_instance_vbo);
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(g.voxels.size() * sizeof(CubeInstance)),
                   g.voxels.data(), GL_STREAM_DRAW);
      glDrawArraysInstanced(GL_TRIANGLES, 0, 36, static_cast<GLsizei>(g.voxels.size()));
    }
    if (!g.volume_triangles.empty()) {
      glUseProgram(shaded.id);
      glUniformMatrix4fv(shaded.clip_from_world, 1, GL_FALSE, clip_from_world.data());
      glUniform3fv(shaded.light, 1, light_f.data());
      glBindVertexArray(shaded_vao);
      glBindBuffer(GL_ARRAY_BUFFER, shaded_vbo);
      glBufferData(GL_ARRAY_BUFFER,
                   static_cast<GLsizeiptr>(g.volume_triangles.size() * sizeof(ShadedVertex)),
                   g.volume_triangles.data(), GL_STREAM_DRAW);
      glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(g.volume_triangles.size()));
    }
    glDepthMask(GL_TRUE);
    glBindVertexArray(0);
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) return Status::Error("viewer GL error " + std::to_string(err));
    return Status::Ok();
  }

  void Annotate(const SceneState& scene, const ViewCamera& camera, const HeightScale& heights,
                cv::Mat* image) const {
    const double font = FontScaleFor(image->cols);
    // Object ids (and speeds) next to each object.
    for (const ObjectData& o : scene.objects().objects) {
      // A detected object has no position estimate yet: labelled at its volume, if any.
      const bool estimated = o.state != ObjectState::kDetected;
      if (!estimated && o.volumes.empty()) continue;
      const Eigen::Vector3d anchor = estimated ? o.position : o.volumes[0].center;
      Eigen::Vector2d px;
      if (!anchor.allFinite() || !camera.Project(anchor, &px)) continue;
      char text[64];
      if (estimated && o.linear_velocity.allFinite()) {
        std::snprintf(text, sizeof(text), "#%d %.2f %s", o.id, o.linear_velocity.norm(),
                      scene.objects().metric ? "m/s" : "u/s");
      } else {
        std::snprintf(text, sizeof(text), "#%d", o.id);
      }
      DrawOutlinedText(image, text,
                       cv::Point(static_cast<int>(px.x()) + 8, static_cast<int>(px.y()) - 8), font,
                       ObjectColor(o.id), 1);
    }
    if (!options.show_legend) return;
    const auto& current = scene.current_camera();
    const char* states[] = {"not initialised", "initialising", "tracking", "lost", "relocalised"};
    const int state = current ? static_cast<int>(current->tracking_state) : 0;
    char header[512];
    std::snprintf(header, sizeof(header),
                  "3D view (%s)  t = %s  camera: %s, %s  |  %zu map points, %zu keyframes, "
                  "%zu objects, %lld voxels",
                  options.camera_mode.c_str(), FormatSeconds(scene.latest_utime()).c_str(),
                  state >= 0 && state <= 4 ? states[state] : "?",
                  scene.metric() ? "metric (m)" : "up to scale (map units)",
                  scene.map().points.size(), scene.map().keyframes.size(),
                  scene.objects().objects.size(),
                  static_cast<long long>(scene.occupancy().num_occupied));
    DrawHeader(image, header, font);
    char height_label[128];
    std::snprintf(height_label, sizeof(height_label), "static points: height %.2f .. %.2f %s",
                  heights.low, heights.high, scene.map().ground_plane ? "above ground" : "(-y)");
    std::vector<LegendEntry> legend = {
        {height_label, HeightColor(0.8), LegendEntry::Kind::kPoint},
        {"camera trajectory / current camera", kCameraTrajectoryColor, LegendEntry::Kind::kLine},
        {"keyframes", kKeyframeColor, LegendEntry::Kind::kLine},
        {"particles (bearing-only tracker)", kParticleColor, LegendEntry::Kind::kPoint},
        {"occupied voxels (height colour)", HeightColor(0.3), LegendEntry::Kind::kBox},
    };
    int shown = 0;
    for (const ObjectData& o : scene.objects().objects) {
      const bool drawn = o.state != ObjectState::kDetected || !o.points.empty() ||
                         !o.particles.empty() || !o.volumes.empty();
      if (!drawn) continue;
      if (shown++ >= 6) break;
      legend.push_back({"object #" + std::to_string(o.id) + ": points, trajectory, volumes",
                        ObjectColor(o.id), LegendEntry::Kind::kBox});
    }
    int baseline = 0;
    const int line =
        cv::getTextSize("Mg", cv::FONT_HERSHEY_SIMPLEX, font, 1, &baseline).height + baseline + 4;
    const int legend_height = line * static_cast<int>(legend.size()) + 8;
    const cv::Point corner(8, std::max(0, image->rows - legend_height - 8));
    DrawLegend(image, legend, corner, font);
  }

  Status Render(const SceneState& scene, const ViewCamera& camera, cv::Mat* bgr) {
    if (camera.width != options.width || camera.height != options.height) {
      return Status::Error("view camera size differs from the renderer's");
    }
    if (!gl->MakeCurrent()) return Status::Error("OSMesa: cannot make the context current");
    const HeightScale heights = ComputeHeightScale(options, scene.map());
    const Eigen::AlignedBox3d bounds = SceneBounds(scene, options.framing_percentile);
    const double scene_scale = LocalScale(scene, bounds);
    const Geometry g = Build(scene, heights, scene_scale);
    // Light from above and slightly from the viewer.
    const Eigen::Vector3d up = UpDirection(scene.map());
    const Eigen::Vector3d to_eye = (camera.eye_in_world() - bounds.center()).normalized();
    Eigen::Vector3d light = 0.8 * up + 0.5 * (to_eye.allFinite() ? to_eye : up);
    light.normalize();
    MBSLAM_RETURN_IF_ERROR(Draw(g, camera, light));
    MBSLAM_RETURN_IF_ERROR(gl->ReadBgr(bgr));
    Annotate(scene, camera, heights, bgr);
    return Status::Ok();
  }
};

View3dRenderer::View3dRenderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
View3dRenderer::~View3dRenderer() = default;

std::unique_ptr<View3dRenderer> View3dRenderer::Create(const View3dOptions& options,
                                                       Status* status) {
  if (!options.Check()) {
    *status = Status::Error("view3d options: " + LastOptionError());
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  *status = impl->Init();
  if (!status->ok()) return nullptr;
  MBSLAM_LOG(DEBUG) << "viewer: 3D view on " << impl->gl->description();
  return std::unique_ptr<View3dRenderer>(new View3dRenderer(std::move(impl)));
}

Status View3dRenderer::Render(const SceneState& scene, cv::Mat* bgr) {
  return impl_->Render(scene, ComputeViewCamera(impl_->options, scene), bgr);
}

Status View3dRenderer::Render(const SceneState& scene, const ViewCamera& camera, cv::Mat* bgr) {
  return impl_->Render(scene, camera, bgr);
}

const std::string& View3dRenderer::gl_description() const { return impl_->gl->description(); }

}  // namespace viewer
}  // namespace mbslam
