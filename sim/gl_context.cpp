#include "sim/gl_context.h"

#include <EGL/eglext.h>

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <string>

namespace costar::sim {

namespace {

std::string eglError(const char* what) {
  return std::string("headless rendering: ") + what + " failed (EGL error 0x" + [] {
    char hex[16];
    std::snprintf(hex, sizeof hex, "%x", eglGetError());
    return std::string(hex);
  }() + "); is Mesa's EGL (libegl-mesa0, libgl1-mesa-dri) installed?";
}

/// The process's one EGL display (EGL gives every caller the same one for a platform) and the
/// number of renderers using it. Made on first use and never destroyed, so that a renderer
/// destroyed during static destruction at exit still finds the lock.
struct SharedDisplay {
  /// Held while a renderer is created or destroyed: the display's initialization, and MuJoCo's
  /// loading of GL functions into its globals (mjr_makeContext).
  std::mutex mutex;
  int users = 0;
  int initializations = 0;
  EGLDisplay display = EGL_NO_DISPLAY;
  EGLConfig config = nullptr;
  /// Contexts of renderers that are gone, current nowhere, kept for the next renderers: a
  /// context keeps the shaders Mesa compiled for it (llvmpipe compiles each GL state's shaders
  /// with LLVM the first time a context draws with it, ~0.15 s of CPU per new context), which
  /// a trial loop (a renderer per trial) paid once per trial.
  std::vector<EGLContext> spare_contexts;
  int contexts_created = 0;
};

/// At most this many contexts kept for reuse (a thread each, for `trials -j N`).
constexpr std::size_t kSpareContexts = 8;

SharedDisplay& sharedDisplay() {
  static auto* shared = new SharedDisplay;  // never destroyed, see above
  return *shared;
}

/// One more user of the display: initializes it for the first. The caller holds the mutex.
void acquireDisplay(SharedDisplay& shared) {
  if (shared.display == EGL_NO_DISPLAY) {
    // Mesa's surfaceless platform: no display server, no GPU needed.
    const auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) {
      throw std::runtime_error("headless rendering: eglGetPlatformDisplayEXT is not available");
    }
    const EGLDisplay display = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    EGLint major = 0;
    EGLint minor = 0;
    if (display == EGL_NO_DISPLAY || eglInitialize(display, &major, &minor) != EGL_TRUE) {
      throw std::runtime_error(eglError("eglInitialize"));
    }
    const EGLint config_attributes[] = {EGL_RED_SIZE,
                                        8,
                                        EGL_GREEN_SIZE,
                                        8,
                                        EGL_BLUE_SIZE,
                                        8,
                                        EGL_ALPHA_SIZE,
                                        8,
                                        EGL_DEPTH_SIZE,
                                        24,
                                        EGL_STENCIL_SIZE,
                                        8,
                                        EGL_COLOR_BUFFER_TYPE,
                                        EGL_RGB_BUFFER,
                                        EGL_SURFACE_TYPE,
                                        EGL_PBUFFER_BIT,
                                        EGL_RENDERABLE_TYPE,
                                        EGL_OPENGL_BIT,
                                        EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (eglChooseConfig(display, config_attributes, &config, 1, &count) != EGL_TRUE || count < 1) {
      const std::string error = eglError("eglChooseConfig");
      eglTerminate(display);
      throw std::runtime_error(error);
    }
    shared.display = display;
    shared.config = config;
    ++shared.initializations;
  }
  ++shared.users;
}

/// One user fewer. The display stays initialized when the last goes, for the next renderer and
/// until the process ends: Mesa keeps about 23 kB of every eglInitialize that eglTerminate does
/// not give back, which a trial loop (a renderer per trial, one at a time) paid once per trial
/// (docs/BENCHMARKS_HISTORY.md, the soak). The caller holds the mutex.
void releaseDisplay(SharedDisplay& shared) { --shared.users; }

}  // namespace

/// Makes a renderer's context current on this thread for a scope, then gives the thread back
/// what it had (normally no context), so that the context is current nowhere between scopes.
class GlRenderer::Current {
 public:
  Current(EGLDisplay display, EGLContext context)
      : display_(display),
        api_(eglQueryAPI()),
        previous_display_(eglGetCurrentDisplay()),
        previous_context_(eglGetCurrentContext()),
        previous_draw_(eglGetCurrentSurface(EGL_DRAW)),
        previous_read_(eglGetCurrentSurface(EGL_READ)) {
    eglBindAPI(EGL_OPENGL_API);  // the bound API is per thread
    if (eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context) != EGL_TRUE) {
      const std::string error = eglError("eglMakeCurrent");
      eglBindAPI(api_);
      throw std::runtime_error(error);
    }
  }
  ~Current() {
    if (previous_context_ != EGL_NO_CONTEXT) {
      eglMakeCurrent(previous_display_, previous_draw_, previous_read_, previous_context_);
    } else {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    eglBindAPI(api_);
  }
  Current(const Current&) = delete;
  Current& operator=(const Current&) = delete;

 private:
  EGLDisplay display_;
  EGLenum api_;
  EGLDisplay previous_display_;
  EGLContext previous_context_;
  EGLSurface previous_draw_;
  EGLSurface previous_read_;
};

GlRenderer::GlRenderer(const mjModel* model) {
  mjv_defaultScene(&scene_);
  mjv_defaultOption(&option_);
  mjv_defaultPerturb(&perturb_);
  mjr_defaultContext(&render_context_);
  for (int group = 0; group < mjNGROUP; ++group) {
    option_.sitegroup[group] = 0;  // sites are markers for people, not surfaces a camera sees
  }
  SharedDisplay& shared = sharedDisplay();
  const std::lock_guard lock(shared.mutex);
  acquireDisplay(shared);
  display_ = shared.display;
  try {
    eglBindAPI(EGL_OPENGL_API);
    if (!shared.spare_contexts.empty()) {
      context_ = shared.spare_contexts.back();
      shared.spare_contexts.pop_back();
    } else {
      context_ = eglCreateContext(display_, shared.config, EGL_NO_CONTEXT, nullptr);
      shared.contexts_created += context_ != EGL_NO_CONTEXT ? 1 : 0;
    }
    if (context_ == EGL_NO_CONTEXT) {
      throw std::runtime_error(eglError("eglCreateContext"));
    }
    const Current current(display_, context_);
    mjv_makeScene(model, &scene_, 4000);
    mjr_makeContext(model, &render_context_, mjFONTSCALE_100);
    mujoco_context_ = true;
    mjr_setBuffer(mjFB_OFFSCREEN, &render_context_);
    if (render_context_.currentBuffer != mjFB_OFFSCREEN) {
      throw std::runtime_error("headless rendering: MuJoCo's offscreen buffer is not supported");
    }
  } catch (...) {
    if (context_ != EGL_NO_CONTEXT) {
      if (mujoco_context_) {
        try {
          const Current current(display_, context_);
          mjr_freeContext(&render_context_);
        } catch (const std::exception&) {
          // Not current: its GL objects go with the context.
        }
      }
      eglDestroyContext(display_, context_);
    }
    mjv_freeScene(&scene_);
    releaseDisplay(shared);
    throw;
  }
}

GlRenderer::~GlRenderer() {
  SharedDisplay& shared = sharedDisplay();
  const std::lock_guard lock(shared.mutex);
  bool freed = false;
  try {
    const Current current(display_, context_);
    mjr_freeContext(&render_context_);
    freed = true;
  } catch (const std::exception& e) {
    // Only when the context is current on another thread, which this class never leaves it:
    // its GL objects go with the context.
    std::fprintf(stderr, "warning: %s (while freeing a renderer)\n", e.what());
  }
  mjv_freeScene(&scene_);
  // A context emptied of MuJoCo's objects is kept for the next renderer (it keeps its compiled
  // shaders); one that could not be emptied, or beyond the spares kept, is destroyed.
  if (freed && shared.spare_contexts.size() < kSpareContexts) {
    shared.spare_contexts.push_back(context_);
  } else {
    eglDestroyContext(display_, context_);
  }
  releaseDisplay(shared);
}

int GlRenderer::displayInitializations() {
  SharedDisplay& shared = sharedDisplay();
  const std::lock_guard lock(shared.mutex);
  return shared.initializations;
}

int GlRenderer::contextsCreated() {
  SharedDisplay& shared = sharedDisplay();
  const std::lock_guard lock(shared.mutex);
  return shared.contexts_created;
}

int GlRenderer::liveCount() {
  SharedDisplay& shared = sharedDisplay();
  const std::lock_guard lock(shared.mutex);
  return shared.users;
}

void GlRenderer::render(const mjModel* model, mjData* data, int camera_id, int width, int height, RgbImage* rgb,
                        std::vector<float>* depth) {
  if (width > render_context_.offWidth || height > render_context_.offHeight || width <= 0 || height <= 0) {
    throw std::runtime_error("cannot render " + std::to_string(width) + "x" + std::to_string(height) +
                             ": the largest image is " + std::to_string(render_context_.offWidth) + "x" +
                             std::to_string(render_context_.offHeight));
  }
  const Current current(display_, context_);
  mjvCamera camera;
  mjv_defaultCamera(&camera);
  camera.type = mjCAMERA_FIXED;
  camera.fixedcamid = camera_id;
  mjv_updateScene(model, data, &option_, &perturb_, &camera, mjCAT_ALL, &scene_);
  // Depth alone: the same surfaces drawn flat, without what only colour needs (shadow maps are
  // a second render of the scene from the light, reflections a third; the skybox, lighting
  // and textures). Depth is the same either way.
  const bool colour = rgb != nullptr;
  // The shadow pass (the scene drawn again from the key light into a 2048 x 2048 map, and a
  // shadow lookup per lit pixel) only in pictures for people: a camera frame's colour is
  // lit without it (about 60 % of its render CPU on llvmpipe).
  scene_.flags[mjRND_SHADOW] = colour && depth == nullptr ? 1 : 0;
  scene_.flags[mjRND_REFLECTION] = colour ? 1 : 0;
  scene_.flags[mjRND_SKYBOX] = colour ? 1 : 0;
  scene_.flags[mjRND_SEGMENT] = colour ? 0 : 1;
  const mjrRect viewport{0, 0, width, height};
  // Depth alone: no colour written (llvmpipe's fragment code then only tests and writes depth).
  // glColorMask from EGL, as MuJoCo takes its GL functions: this library links no GL library.
  using ColorMask = void (*)(unsigned char, unsigned char, unsigned char, unsigned char);
  static const auto color_mask = reinterpret_cast<ColorMask>(eglGetProcAddress("glColorMask"));
  if (!colour && color_mask != nullptr) {
    color_mask(0, 0, 0, 0);
  }
  mjr_render(viewport, &scene_, &render_context_);
  if (!colour && color_mask != nullptr) {
    color_mask(1, 1, 1, 1);
  }
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  if (colour) {
    rgb_buffer_.resize(pixels * 3);
  }
  if (depth != nullptr) {
    depth_buffer_.resize(pixels);
  }
  mjr_readPixels(colour ? rgb_buffer_.data() : nullptr, depth != nullptr ? depth_buffer_.data() : nullptr, viewport,
                 &render_context_);

  // OpenGL's rows go bottom-up; images go top-down.
  if (colour) {
    *rgb = RgbImage(width, height);
    for (int y = 0; y < height; ++y) {
      std::copy_n(&rgb_buffer_[static_cast<std::size_t>(height - 1 - y) * width * 3], width * 3, rgb->at(0, y));
    }
  }
  if (depth != nullptr) {
    // Depth buffer value d -> distance along the optical axis.
    const double extent = model->stat.extent;
    const double near = model->vis.map.znear * extent;
    const double far = model->vis.map.zfar * extent;
    depth->resize(pixels);
    const double scale = 1.0 - near / far;
    for (int y = 0; y < height; ++y) {
      const float* row = &depth_buffer_[static_cast<std::size_t>(height - 1 - y) * width];
      float* out = depth->data() + static_cast<std::size_t>(y) * width;
      for (int x = 0; x < width; ++x) {
        const double d = row[x];
        out[x] = d >= 1.0 ? 0.0f : static_cast<float>(near / (1.0 - d * scale));
      }
    }
  }
}

}  // namespace costar::sim
