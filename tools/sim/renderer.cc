#include "tools/sim/renderer.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <string>

#include "common/util/logging.h"

namespace mbslam {
namespace sim {
namespace {

constexpr GLenum kMaxAnisotropy = 0x84FE;  // GL_TEXTURE_MAX_ANISOTROPY(_EXT)

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec2 a_uv;
layout(location = 2) in vec2 a_detail_uv;
uniform mat4 u_clip_from_body;
uniform mat4 u_cam_from_body;
out vec3 v_point_in_cam;
out vec2 v_uv;
out vec2 v_detail_uv;
void main() {
  vec4 p = vec4(a_position, 1.0);
  v_point_in_cam = (u_cam_from_body * p).xyz;
  v_uv = a_uv;
  v_detail_uv = a_detail_uv;
  gl_Position = u_clip_from_body * p;
}
)";

// Colour pass: textured albedo times a fine detail texture, flat Lambert shade per quad.
// The surface texture is filtered anisotropically by hand (4 trilinear taps along the
// longer axis of the pixel's footprint, at the mip level of its shorter axis): without
// it, ground seen at grazing angles blurs away; llvmpipe's own anisotropic filtering
// costs ~50x more.
const char* kColorFragmentShader = R"(#version 330 core
in vec3 v_point_in_cam;
in vec2 v_uv;
in vec2 v_detail_uv;
uniform sampler2D u_texture;
uniform sampler2D u_detail;
uniform float u_shade;
uniform float u_detail_strength;
uniform int u_anisotropic_taps;
layout(location = 0) out vec4 o_out;

vec3 SampleAnisotropic(sampler2D tex, vec2 uv, int taps) {
  vec2 size = vec2(textureSize(tex, 0));
  vec2 du = dFdx(uv), dv = dFdy(uv);
  float lx = length(du * size), ly = length(dv * size);
  float major = max(lx, ly), minor = max(min(lx, ly), 1e-6);
  vec2 axis = lx > ly ? du : dv;
  float n = float(taps);
  float lod = log2(max(max(major / n, minor), 1e-6));
  vec3 sum = vec3(0.0);
  for (int i = 0; i < taps; ++i) {
    sum += textureLod(tex, uv + axis * ((float(i) + 0.5) / n - 0.5), lod).rgb;
  }
  return sum / n;
}

void main() {
  vec3 albedo = u_anisotropic_taps > 1 ? SampleAnisotropic(u_texture, v_uv, u_anisotropic_taps)
                                       : texture(u_texture, v_uv).rgb;
  float d = texture(u_detail, v_detail_uv).r;
  albedo *= 1.0 + u_detail_strength * (2.0 * d - 1.0);
  o_out = vec4(clamp(albedo * u_shade, 0.0, 1.0), 1.0);
}
)";

// Geometry pass: the surface point in the camera frame and the body id, as floats.
const char* kGeometryFragmentShader = R"(#version 330 core
in vec3 v_point_in_cam;
in vec2 v_uv;
in vec2 v_detail_uv;
uniform float u_body_id;
layout(location = 0) out vec4 o_out;
void main() {
  o_out = vec4(v_point_in_cam, u_body_id);
}
)";

Status CompileShader(GLenum type, const char* source, GLuint* shader) {
  *shader = glCreateShader(type);
  glShaderSource(*shader, 1, &source, nullptr);
  glCompileShader(*shader);
  GLint ok = 0;
  glGetShaderiv(*shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {0};
    glGetShaderInfoLog(*shader, sizeof(log), nullptr, log);
    return Status::Error(std::string("shader compilation failed: ") + log);
  }
  return Status::Ok();
}

// A detail texture: fine multi-octave noise with small blobs (grey, R8).
cv::Mat MakeDetailTexture(int size, uint64_t seed) {
  cv::Mat noise = FractalNoise(size, size, seed, 48.0, 6, 0.75);
  cv::Mat out;
  noise.convertTo(out, CV_8U, 40.0, 128.0);
  return out;
}

struct QuadDraw {
  size_t body = 0;
  size_t quad = 0;
  GLint first_vertex = 0;
  GLuint texture = 0;
};

}  // namespace

struct Renderer::Impl {
  const Scene* scene = nullptr;
  CameraIntrinsics intrinsics;
  RendererOptions options;
  OSMesaContext context = nullptr;
  std::vector<uint8_t> default_buffer;
  // One program per pass; uniform locations of each.
  struct Program {
    GLuint id = 0, vertex_shader = 0, fragment_shader = 0;
    GLint clip_from_body = -1, cam_from_body = -1, shade = -1, detail_strength = -1, body_id = -1,
          texture = -1, detail = -1, anisotropic_taps = -1;
  };
  Program color_program, geometry_program;
  GLuint vao = 0, vbo = 0;
  std::vector<GLuint> textures;
  GLuint detail_texture = 0;
  GLuint color_fbo = 0, color_rb = 0, color_depth_rb = 0;  // possibly multisampled
  GLuint resolve_fbo = 0, resolve_rb = 0;                  // single-sample colour
  GLuint geometry_fbo = 0, geometry_rb = 0, geometry_depth_rb = 0;
  std::vector<QuadDraw> draws;
  Eigen::Matrix4d cam_to_clip = Eigen::Matrix4d::Zero();
  std::vector<float> read_buffer;

  ~Impl() {
    if (!context) {
      return;
    }
    if (MakeCurrent()) {
      if (!textures.empty()) {
        glDeleteTextures(static_cast<GLsizei>(textures.size()), textures.data());
      }
      glDeleteTextures(1, &detail_texture);
      GLuint rbs[] = {color_rb, color_depth_rb, resolve_rb, geometry_rb, geometry_depth_rb};
      glDeleteRenderbuffers(5, rbs);
      GLuint fbos[] = {color_fbo, resolve_fbo, geometry_fbo};
      glDeleteFramebuffers(3, fbos);
      glDeleteBuffers(1, &vbo);
      glDeleteVertexArrays(1, &vao);
      for (Program* p : {&color_program, &geometry_program}) {
        glDeleteProgram(p->id);
        glDeleteShader(p->vertex_shader);
        glDeleteShader(p->fragment_shader);
      }
    }
    OSMesaDestroyContext(context);
  }

  bool MakeCurrent() {
    return OSMesaMakeCurrent(context, default_buffer.data(), GL_UNSIGNED_BYTE, 4, 4) == GL_TRUE;
  }

  Status Init() {
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           4,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           5,
                           0};
    context = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!context) {
      return Status::Error("OSMesa: cannot create a GL 4.5 core context");
    }
    default_buffer.assign(size_t{4} * 4 * 4, 0);
    if (!MakeCurrent()) {
      return Status::Error("OSMesa: cannot make the context current");
    }

    MBSLAM_RETURN_IF_ERROR(BuildProgram(kColorFragmentShader, &color_program));
    MBSLAM_RETURN_IF_ERROR(BuildProgram(kGeometryFragmentShader, &geometry_program));
    MBSLAM_RETURN_IF_ERROR(UploadGeometry());
    MBSLAM_RETURN_IF_ERROR(UploadTextures());
    MBSLAM_RETURN_IF_ERROR(CreateFramebuffers());

    // Pinhole projection with the pixel-centre convention and reversed z in [0, 1]:
    // window x = u + 0.5, window y = height - v - 0.5 (rows are flipped on read-back),
    // depth = near / z (1 at the near plane, 0 at infinity).
    const double w = intrinsics.width, h = intrinsics.height;
    cam_to_clip << 2.0 * intrinsics.fx / w, 0.0, 2.0 * (intrinsics.cx + 0.5) / w - 1.0, 0.0,  //
        0.0, -2.0 * intrinsics.fy / h, 1.0 - 2.0 * (intrinsics.cy + 0.5) / h, 0.0,            //
        0.0, 0.0, 0.0, options.near_m,                                                        //
        0.0, 0.0, 1.0, 0.0;
    // glClipControl (GL 4.5) is not exported by libOSMesa: fetch it from the driver.
    using ClipControlFn = void (*)(GLenum, GLenum);
    const auto clip_control =
        reinterpret_cast<ClipControlFn>(OSMesaGetProcAddress("glClipControl"));
    if (!clip_control) {
      return Status::Error("OSMesa: glClipControl is not available");
    }
    clip_control(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
      return Status::Error("GL error during set-up: " + std::to_string(err));
    }
    return Status::Ok();
  }

  static Status BuildProgram(const char* fragment_source, Program* p) {
    MBSLAM_RETURN_IF_ERROR(CompileShader(GL_VERTEX_SHADER, kVertexShader, &p->vertex_shader));
    MBSLAM_RETURN_IF_ERROR(CompileShader(GL_FRAGMENT_SHADER, fragment_source, &p->fragment_shader));
    p->id = glCreateProgram();
    glAttachShader(p->id, p->vertex_shader);
    glAttachShader(p->id, p->fragment_shader);
    glLinkProgram(p->id);
    GLint linked = 0;
    glGetProgramiv(p->id, GL_LINK_STATUS, &linked);
    if (!linked) {
      char log[2048] = {0};
      glGetProgramInfoLog(p->id, sizeof(log), nullptr, log);
      return Status::Error(std::string("shader link failed: ") + log);
    }
    p->clip_from_body = glGetUniformLocation(p->id, "u_clip_from_body");
    p->cam_from_body = glGetUniformLocation(p->id, "u_cam_from_body");
    p->shade = glGetUniformLocation(p->id, "u_shade");
    p->detail_strength = glGetUniformLocation(p->id, "u_detail_strength");
    p->body_id = glGetUniformLocation(p->id, "u_body_id");
    p->texture = glGetUniformLocation(p->id, "u_texture");
    p->detail = glGetUniformLocation(p->id, "u_detail");
    p->anisotropic_taps = glGetUniformLocation(p->id, "u_anisotropic_taps");
    return Status::Ok();
  }

  Status UploadGeometry() {
    std::vector<float> vertices;  // x y z, u v, du dv
    uint64_t hash = 0x12345;
    for (size_t b = 0; b < scene->bodies.size(); ++b) {
      const auto& quads = scene->bodies[b].quads;
      for (size_t k = 0; k < quads.size(); ++k) {
        const Quad& q = quads[k];
        if (q.texture < 0 || q.texture >= static_cast<int>(scene->textures.size())) {
          return Status::Error("quad without a valid texture in body " + std::to_string(b));
        }
        QuadDraw draw;
        draw.body = b;
        draw.quad = k;
        draw.first_vertex = static_cast<GLint>(vertices.size() / 7);
        draws.push_back(draw);
        hash = hash * 6364136223846793005ULL + 1442695040888963407ULL;
        const double off_u = static_cast<double>((hash >> 20) & 0xFFFF) / 65536.0;
        const double off_v = static_cast<double>((hash >> 40) & 0xFFFF) / 65536.0;
        const double lu = q.edge_u.norm() / options.detail_period_m;
        const double lv = q.edge_v.norm() / options.detail_period_m;
        const double corners[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // counter-clockwise
        for (const auto& c : corners) {
          const Eigen::Vector3d p = q.Point(c[0], c[1]);
          vertices.insert(
              vertices.end(),
              {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()),
               static_cast<float>(c[0]), static_cast<float>(1.0 - c[1]),
               static_cast<float>(off_u + c[0] * lu), static_cast<float>(off_v + c[1] * lv)});
        }
      }
    }
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(float)),
                 vertices.data(), GL_STATIC_DRAW);
    const GLsizei stride = 7 * sizeof(float);
    // Offsets into the bound buffer, passed as pointers (the GL API).
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    glVertexAttribPointer(
        1, 2, GL_FLOAT, GL_FALSE, stride,
        reinterpret_cast<void*>(3 * sizeof(float)));  // NOLINT(performance-no-int-to-ptr)
    glVertexAttribPointer(
        2, 2, GL_FLOAT, GL_FALSE, stride,
        reinterpret_cast<void*>(5 * sizeof(float)));  // NOLINT(performance-no-int-to-ptr)
    glEnableVertexAttribArray(0);
    glEnableVertexAttribArray(1);
    glEnableVertexAttribArray(2);
    return Status::Ok();
  }

  Status UploadTextures() {
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    textures.resize(scene->textures.size());
    glGenTextures(static_cast<GLsizei>(textures.size()), textures.data());
    for (size_t i = 0; i < textures.size(); ++i) {
      const cv::Mat& img = scene->textures[i];
      if (img.type() != CV_8UC3 || !img.isContinuous()) {
        return Status::Error("texture " + std::to_string(i) + " is not continuous BGR 8-bit");
      }
      glBindTexture(GL_TEXTURE_2D, textures[i]);
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB8, img.cols, img.rows, 0, GL_BGR, GL_UNSIGNED_BYTE,
                   img.data);
      glGenerateMipmap(GL_TEXTURE_2D);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glTexParameterf(GL_TEXTURE_2D, kMaxAnisotropy, static_cast<float>(options.anisotropy));
    }
    for (auto& d : draws) {
      d.texture = textures[static_cast<size_t>(scene->bodies[d.body].quads[d.quad].texture)];
    }
    const cv::Mat detail = MakeDetailTexture(1024, 7);
    glGenTextures(1, &detail_texture);
    glBindTexture(GL_TEXTURE_2D, detail_texture);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, detail.cols, detail.rows, 0, GL_RED, GL_UNSIGNED_BYTE,
                 detail.data);
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glTexParameterf(GL_TEXTURE_2D, kMaxAnisotropy, static_cast<float>(options.anisotropy));
    return Status::Ok();
  }

  Status CreateFramebuffers() {
    const GLsizei w = intrinsics.width, h = intrinsics.height;
    const GLsizei samples = options.antialias_samples > 1 ? options.antialias_samples : 0;
    glGenFramebuffers(1, &color_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, color_fbo);
    glGenRenderbuffers(1, &color_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, color_rb);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb);
    glGenRenderbuffers(1, &color_depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, color_depth_rb);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT32F, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, color_depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Status::Error("colour framebuffer incomplete");
    }
    glGenFramebuffers(1, &resolve_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
    glGenRenderbuffers(1, &resolve_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, resolve_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolve_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Status::Error("resolve framebuffer incomplete");
    }
    glGenFramebuffers(1, &geometry_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, geometry_fbo);
    glGenRenderbuffers(1, &geometry_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, geometry_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, geometry_rb);
    glGenRenderbuffers(1, &geometry_depth_rb);
    glBindRenderbuffer(GL_RENDERBUFFER, geometry_depth_rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, w, h);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                              geometry_depth_rb);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Status::Error("geometry framebuffer incomplete");
    }
    return Status::Ok();
  }

  // True if all four corners are outside one of the clip planes.
  static bool Culled(const Eigen::Matrix4d& clip_from_body, const Quad& q) {
    Eigen::Matrix4d corners;
    corners.col(0) << q.origin, 1.0;
    corners.col(1) << q.origin + q.edge_u, 1.0;
    corners.col(2) << q.origin + q.edge_u + q.edge_v, 1.0;
    corners.col(3) << q.origin + q.edge_v, 1.0;
    const Eigen::Matrix4d c = clip_from_body * corners;
    bool left = true, right = true, bottom = true, top = true, behind = true;
    for (int i = 0; i < 4; ++i) {
      const double x = c(0, i), y = c(1, i), z = c(2, i), w = c(3, i);
      left = left && x < -w;
      right = right && x > w;
      bottom = bottom && y < -w;
      top = top && y > w;
      behind = behind && z > w;  // reversed z: z_clip = near, in front iff w >= near
    }
    return left || right || bottom || top || behind;
  }

  Status DrawScene(const std::vector<Rigid3d>& cam_from_body, bool geometry) {
    if (cam_from_body.size() != scene->bodies.size()) {
      return Status::Error("renderer: expected " + std::to_string(scene->bodies.size()) +
                           " body poses, got " + std::to_string(cam_from_body.size()));
    }
    glViewport(0, 0, intrinsics.width, intrinsics.height);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    const Program& p = geometry ? geometry_program : color_program;
    glUseProgram(p.id);
    glBindVertexArray(vao);
    if (!geometry) {
      glUniform1i(p.texture, 0);
      glUniform1i(p.detail, 1);
      glUniform1f(p.detail_strength, static_cast<float>(options.detail_strength));
      glUniform1i(p.anisotropic_taps, options.anisotropic_taps);
    }
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, detail_texture);
    glActiveTexture(GL_TEXTURE0);
    // Light direction in the camera frame (body 0 is the static world at identity).
    const Eigen::Vector3d light_in_cam = cam_from_body[0].rotation * scene->light_direction;
    size_t current_body = static_cast<size_t>(-1);
    Eigen::Matrix4d clip_from_body;
    for (const QuadDraw& d : draws) {
      if (d.body != current_body) {
        current_body = d.body;
        const Eigen::Matrix4d cam = cam_from_body[d.body].ToMatrix();
        clip_from_body = cam_to_clip * cam;
        const Eigen::Matrix4f clip_f = clip_from_body.cast<float>();
        const Eigen::Matrix4f cam_f = cam.cast<float>();
        glUniformMatrix4fv(p.clip_from_body, 1, GL_FALSE, clip_f.data());
        glUniformMatrix4fv(p.cam_from_body, 1, GL_FALSE, cam_f.data());
        if (geometry) {
          glUniform1f(p.body_id, static_cast<float>(scene->bodies[d.body].id));
        }
      }
      const Quad& q = scene->bodies[d.body].quads[d.quad];
      if (Culled(clip_from_body, q)) {
        continue;
      }
      if (!geometry) {
        const Eigen::Vector3d n = cam_from_body[d.body].rotation * q.Normal();
        const double shade =
            scene->ambient + (1.0 - scene->ambient) * std::max(0.0, n.dot(light_in_cam));
        glUniform1f(p.shade, static_cast<float>(shade));
        glBindTexture(GL_TEXTURE_2D, d.texture);
      }
      glDrawArrays(GL_TRIANGLE_FAN, d.first_vertex, 4);
    }
    const GLenum err = glGetError();
    if (err != GL_NO_ERROR) {
      return Status::Error("GL error while drawing: " + std::to_string(err));
    }
    return Status::Ok();
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

std::unique_ptr<Renderer> Renderer::Create(const Scene& scene, const CameraIntrinsics& intrinsics,
                                           const RendererOptions& options, Status* status) {
  *status = intrinsics.Validate();
  if (!status->ok()) {
    return nullptr;
  }
  if (intrinsics.HasDistortion()) {
    *status = Status::Error("renderer: distorted cameras are not supported");
    return nullptr;
  }
  if (!options.Check()) {
    *status = Status::Error("renderer options: " + LastOptionError());
    return nullptr;
  }
  if (scene.bodies.empty() || scene.bodies[0].id != 0) {
    *status = Status::Error("renderer: bodies[0] must be the static world (id 0)");
    return nullptr;
  }
  auto impl = std::make_unique<Impl>();
  impl->scene = &scene;
  impl->intrinsics = intrinsics;
  impl->options = options;
  *status = impl->Init();
  if (!status->ok()) {
    return nullptr;
  }
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

Status Renderer::RenderColor(const std::vector<Rigid3d>& cam_from_body, cv::Mat* bgr) {
  Impl& m = *impl_;
  if (!m.MakeCurrent()) {
    return Status::Error("OSMesa: cannot make the context current");
  }
  const int w = m.intrinsics.width, h = m.intrinsics.height;
  glBindFramebuffer(GL_FRAMEBUFFER, m.color_fbo);
  const GLfloat sky[4] = {static_cast<GLfloat>(m.options.sky_bgr[2]),
                          static_cast<GLfloat>(m.options.sky_bgr[1]),
                          static_cast<GLfloat>(m.options.sky_bgr[0]), 1.0f};
  glClearBufferfv(GL_COLOR, 0, sky);
  const GLfloat zero = 0.0f;
  glClearBufferfv(GL_DEPTH, 0, &zero);
  MBSLAM_RETURN_IF_ERROR(m.DrawScene(cam_from_body, false));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.color_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, m.resolve_fbo);
  glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.resolve_fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  cv::Mat bgra(h, w, CV_8UC4);
  glReadPixels(0, 0, w, h, GL_BGRA, GL_UNSIGNED_BYTE, bgra.data);
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    return Status::Error("GL error reading the colour image: " + std::to_string(err));
  }
  cv::flip(bgra, bgra, 0);
  cv::cvtColor(bgra, *bgr, cv::COLOR_BGRA2BGR);
  return Status::Ok();
}

Status Renderer::RenderGeometry(const std::vector<Rigid3d>& cam_from_body, cv::Mat* body_id,
                                cv::Mat* points_in_cam) {
  Impl& m = *impl_;
  if (!m.MakeCurrent()) {
    return Status::Error("OSMesa: cannot make the context current");
  }
  const int w = m.intrinsics.width, h = m.intrinsics.height;
  glBindFramebuffer(GL_FRAMEBUFFER, m.geometry_fbo);
  const GLfloat clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  glClearBufferfv(GL_COLOR, 0, clear);
  const GLfloat zero = 0.0f;
  glClearBufferfv(GL_DEPTH, 0, &zero);
  MBSLAM_RETURN_IF_ERROR(m.DrawScene(cam_from_body, true));
  glBindFramebuffer(GL_READ_FRAMEBUFFER, m.geometry_fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  cv::Mat geom(h, w, CV_32FC4);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, geom.data);
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    return Status::Error("GL error reading the geometry: " + std::to_string(err));
  }
  body_id->create(h, w, CV_16UC1);
  points_in_cam->create(h, w, CV_32FC3);
  for (int r = 0; r < h; ++r) {
    const cv::Vec4f* src = geom.ptr<cv::Vec4f>(h - 1 - r);
    uint16_t* id = body_id->ptr<uint16_t>(r);
    cv::Vec3f* p = points_in_cam->ptr<cv::Vec3f>(r);
    for (int c = 0; c < w; ++c) {
      id[c] = static_cast<uint16_t>(std::lround(std::max(0.0f, src[c][3])));
      p[c] = cv::Vec3f(src[c][0], src[c][1], src[c][2]);
    }
  }
  return Status::Ok();
}

}  // namespace sim
}  // namespace mbslam
