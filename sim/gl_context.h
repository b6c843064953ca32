#pragma once
// Headless OpenGL rendering of a MuJoCo model (internal to sim/): an EGL context on Mesa's
// surfaceless platform and MuJoCo's offscreen buffer.
//
// Ownership and threads (issue 10: a crash in libEGL_mesa with `trials -j 2`, and "terminate
// ... eglMakeCurrent failed" when `costar serve` stopped):
// - The EGL display is one per process (EGL hands every caller the same one). Every renderer
//   holds a reference to it; it is initialized with the first, under one lock, and never
//   terminated (Mesa leaks about 23 kB per initialize/terminate cycle: a trial loop grew by
//   that much per trial), so no renderer ever sees it terminated.
// - A renderer's context is current on the calling thread only inside render() (and while it
//   is created and destroyed): at any other time it is current on no thread. A renderer may
//   therefore be created, used and destroyed on different threads, one thread at a time; two
//   renderers render on two threads at once.
// - Teardown order: MuJoCo's GL objects, then the context (kept, current nowhere, for the next
//   renderer, up to a few), then (with the last renderer) the display's user count. The
//   destructor never throws.

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
  /// only depth is rendered (flat, no shadows: faster, the same depth). Shadows are cast only
  /// in a colour picture without depth (a view for people): a camera frame (colour and depth)
  /// is lit without them, which takes 60 % of a colour frame's render CPU off and leaves
  /// DetectObjects' results as they were (docs/BENCHMARKS_HISTORY.md, issue 13). Not for two threads
  /// at once on one renderer.
  void render(const mjModel* model, mjData* data, int camera_id, int width, int height, RgbImage* rgb,
              std::vector<float>* depth);

  /// Renderers alive in this process.
  static int liveCount();
  /// How many times this process initialized the EGL display (1 once any renderer was made).
  static int displayInitializations();
  /// GL contexts this process created. A renderer takes the context of one that is gone when
  /// there is one (emptied of MuJoCo's objects; Mesa's compiled shaders stay with it), so a
  /// trial loop makes one context per thread, not one per trial.
  static int contextsCreated();

 private:
  class Current;  // makes the context current on this thread for a scope

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
  bool mujoco_context_ = false;
  mjvScene scene_;
  mjvOption option_;
  mjvPerturb perturb_;
  mjrContext render_context_;
  std::vector<unsigned char> rgb_buffer_;
  std::vector<float> depth_buffer_;
};

}  // namespace costar::sim
