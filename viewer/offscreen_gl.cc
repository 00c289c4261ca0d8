#include "viewer/offscreen_gl.h"

#define GL_GLEXT_PROTOTYPES 1
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>

#include <opencv2/imgproc.hpp>

#include <vector>

namespace mbslam {
namespace viewer {

std::unique_ptr<OffscreenGl> OffscreenGl::Create(int width, int height, int samples,
                                                 Status* status) {
  if (width <= 0 || height <= 0 || width > 16384 || height > 16384) {
    *status = Status::Error("offscreen GL: bad size " + std::to_string(width) + "x" +
                            std::to_string(height));
    return nullptr;
  }
  if (samples != 1 && samples != 2 && samples != 4) {
    *status = Status::Error("offscreen GL: samples must be 1, 2 or 4");
    return nullptr;
  }
  std::unique_ptr<OffscreenGl> gl(new OffscreenGl());
  *status = gl->Init(width, height, samples);
  if (!status->ok()) return nullptr;
  return gl;
}

OffscreenGl::~OffscreenGl() {
  if (!context_) return;
  if (MakeCurrent()) {
    const GLuint rbs[] = {draw_color_rb_, draw_depth_rb_, resolve_color_rb_};
    glDeleteRenderbuffers(3, rbs);
    const GLuint fbos[] = {draw_fbo_, resolve_fbo_};
    glDeleteFramebuffers(2, fbos);
  }
  OSMesaDestroyContext(static_cast<OSMesaContext>(context_));
}

bool OffscreenGl::MakeCurrent() {
  // The context's own (default) framebuffer is a 1x1 dummy: drawing goes to the FBOs.
  return OSMesaMakeCurrent(static_cast<OSMesaContext>(context_), dummy_buffer_.data(),
                           GL_UNSIGNED_BYTE, 1, 1) == GL_TRUE;
}

Status OffscreenGl::Init(int width, int height, int samples) {
  width_ = width;
  height_ = height;
  samples_ = samples;
  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_COMPAT_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         3,
                         0};
  context_ = OSMesaCreateContextAttribs(attribs, nullptr);
  if (!context_) return Status::Error("OSMesa: cannot create a GL 3.3 compatibility context");
  dummy_buffer_.assign(4, 0);
  if (!MakeCurrent()) return Status::Error("OSMesa: cannot make the context current");
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  if (!renderer || !version) {
    return Status::Error("OSMesa: glGetString returned NULL (is libGL linked besides OSMesa?)");
  }
  description_ = std::string(renderer) + ", GL " + version;

  const GLsizei ms = samples > 1 ? samples : 0;
  glGenFramebuffers(1, &draw_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glGenRenderbuffers(1, &draw_color_rb_);
  glBindRenderbuffer(GL_RENDERBUFFER, draw_color_rb_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, ms, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, draw_color_rb_);
  glGenRenderbuffers(1, &draw_depth_rb_);
  glBindRenderbuffer(GL_RENDERBUFFER, draw_depth_rb_);
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, ms, GL_DEPTH_COMPONENT32F, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, draw_depth_rb_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return Status::Error("offscreen GL: drawing framebuffer incomplete");
  }
  glGenFramebuffers(1, &resolve_fbo_);
  glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo_);
  glGenRenderbuffers(1, &resolve_color_rb_);
  glBindRenderbuffer(GL_RENDERBUFFER, resolve_color_rb_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                            resolve_color_rb_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    return Status::Error("offscreen GL: resolve framebuffer incomplete");
  }
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    return Status::Error("offscreen GL: error " + std::to_string(err) + " during set-up");
  }
  return Status::Ok();
}

void OffscreenGl::BindTarget() {
  glBindFramebuffer(GL_FRAMEBUFFER, draw_fbo_);
  glViewport(0, 0, width_, height_);
}

Status OffscreenGl::ReadBgr(cv::Mat* bgr) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, draw_fbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo_);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  cv::Mat rgba(height_, width_, CV_8UC4);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  const GLenum err = glGetError();
  if (err != GL_NO_ERROR) {
    return Status::Error("offscreen GL: error " + std::to_string(err) + " reading the image");
  }
  cv::flip(rgba, rgba, 0);
  cv::cvtColor(rgba, *bgr, cv::COLOR_RGBA2BGR);
  return Status::Ok();
}

}  // namespace viewer
}  // namespace mbslam
