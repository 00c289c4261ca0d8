#ifndef MBSLAM_VIEWER_OFFSCREEN_GL_H_
#define MBSLAM_VIEWER_OFFSCREEN_GL_H_

// An OSMesa (llvmpipe) OpenGL context that draws into a multisampled framebuffer object
// and reads the result back as a BGR image. Compatibility profile (GL 3.3+): wide lines
// and point sprites are available. Only OSMesa is linked (never libGL: with both,
// glGetString returns NULL). One context per object; MakeCurrent() before drawing.

#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

#include "common/util/status.h"

namespace mbslam {
namespace viewer {

class OffscreenGl {
 public:
  // samples: 1 (no multisampling), 2 or 4.
  static std::unique_ptr<OffscreenGl> Create(int width, int height, int samples, Status* status);
  ~OffscreenGl();
  OffscreenGl(const OffscreenGl&) = delete;
  OffscreenGl& operator=(const OffscreenGl&) = delete;

  bool MakeCurrent();
  // Binds the drawing framebuffer and sets the viewport to the whole image.
  void BindTarget();
  // Resolves the multisampled image, reads it back, flips rows (GL's origin is the
  // bottom-left) and converts RGBA to BGR.
  Status ReadBgr(cv::Mat* bgr);

  int width() const { return width_; }
  int height() const { return height_; }
  // GL_RENDERER / GL_VERSION, for logs.
  const std::string& description() const { return description_; }

 private:
  OffscreenGl() = default;
  Status Init(int width, int height, int samples);

  void* context_ = nullptr;  // OSMesaContext
  std::vector<unsigned char> dummy_buffer_;
  int width_ = 0, height_ = 0, samples_ = 1;
  unsigned draw_fbo_ = 0, draw_color_rb_ = 0, draw_depth_rb_ = 0;
  unsigned resolve_fbo_ = 0, resolve_color_rb_ = 0;
  std::string description_;
};

}  // namespace viewer
}  // namespace mbslam

#endif  // MBSLAM_VIEWER_OFFSCREEN_GL_H_
