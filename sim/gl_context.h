#pragma once
// Headless OpenGL rendering of a MuJoCo model (internal to sim/): an EGL context on Mesa's
// surfaceless platform and MuJoCo's offscreen buffer.

#include <EGL/egl.h>
#include <mujoco/mujoco.h>

#include <vector>

#include "core/image.h"

namespace costar::sim {

class GlRenderer {
 public:
  /// Creates the GL context and MuJoCo's render context for `model`.
  /// @throws std::runtime_error when no headless GL is available (with what failed).
  explicit GlRenderer(const mjModel* model);
  ~GlRenderer();
  GlRenderer(const GlRenderer&) = delete;
  GlRenderer& operator=(const GlRenderer&) = delete;

  /// Renders camera `camera_id` at width x height (at most the model's offscreen size).
  /// `rgb`, if given, receives the colour image; `depth`, if given, metric depth along the
  /// optical axis, row-major, top row first. The image rows are top first too. Without `rgb`
  /// only depth is rendered (flat, no shadows: faster, the same depth).
  void render(const mjModel* model, mjData* data, int camera_id, int width, int height, RgbImage* rgb,
              std::vector<float>* depth);

 private:
  void makeCurrent();

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  mjvScene scene_;
  mjvOption option_;
  mjvPerturb perturb_;
  mjrContext render_context_;
  std::vector<unsigned char> rgb_buffer_;
  std::vector<float> depth_buffer_;
};

}  // namespace costar::sim
