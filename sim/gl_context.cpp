#include "sim/gl_context.h"

#include <EGL/eglext.h>

#include <algorithm>
#include <cstdio>
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

}  // namespace

GlRenderer::GlRenderer(const mjModel* model) {
  // Mesa's surfaceless platform: no display server, no GPU needed.
  const auto get_platform_display =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (get_platform_display == nullptr) {
    throw std::runtime_error("headless rendering: eglGetPlatformDisplayEXT is not available");
  }
  display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  EGLint major = 0;
  EGLint minor = 0;
  if (display_ == EGL_NO_DISPLAY || eglInitialize(display_, &major, &minor) != EGL_TRUE) {
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
  EGLConfig config;
  EGLint count = 0;
  if (eglChooseConfig(display_, config_attributes, &config, 1, &count) != EGL_TRUE || count < 1) {
    eglTerminate(display_);
    throw std::runtime_error(eglError("eglChooseConfig"));
  }
  eglBindAPI(EGL_OPENGL_API);
  context_ = eglCreateContext(display_, config, EGL_NO_CONTEXT, nullptr);
  if (context_ == EGL_NO_CONTEXT) {
    eglTerminate(display_);
    throw std::runtime_error(eglError("eglCreateContext"));
  }
  makeCurrent();

  mjv_defaultScene(&scene_);
  mjv_defaultOption(&option_);
  mjv_defaultPerturb(&perturb_);
  mjr_defaultContext(&render_context_);
  for (int group = 0; group < mjNGROUP; ++group) {
    option_.sitegroup[group] = 0;  // sites are markers for people, not surfaces a camera sees
  }
  mjv_makeScene(model, &scene_, 4000);
  mjr_makeContext(model, &render_context_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &render_context_);
  if (render_context_.currentBuffer != mjFB_OFFSCREEN) {
    throw std::runtime_error("headless rendering: MuJoCo's offscreen buffer is not supported");
  }
}

GlRenderer::~GlRenderer() {
  makeCurrent();
  mjr_freeContext(&render_context_);
  mjv_freeScene(&scene_);
  eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display_, context_);
  eglTerminate(display_);
}

void GlRenderer::makeCurrent() {
  if (eglGetCurrentContext() != context_ &&
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_) != EGL_TRUE) {
    throw std::runtime_error(eglError("eglMakeCurrent"));
  }
}

void GlRenderer::render(const mjModel* model, mjData* data, int camera_id, int width, int height, RgbImage* rgb,
                        std::vector<float>* depth) {
  if (width > render_context_.offWidth || height > render_context_.offHeight || width <= 0 || height <= 0) {
    throw std::runtime_error("cannot render " + std::to_string(width) + "x" + std::to_string(height) +
                             ": the largest image is " + std::to_string(render_context_.offWidth) + "x" +
                             std::to_string(render_context_.offHeight));
  }
  makeCurrent();
  mjvCamera camera;
  mjv_defaultCamera(&camera);
  camera.type = mjCAMERA_FIXED;
  camera.fixedcamid = camera_id;
  mjv_updateScene(model, data, &option_, &perturb_, &camera, mjCAT_ALL, &scene_);
  // Depth alone: the same surfaces drawn flat, without what only colour needs (shadow maps are
  // a second render of the scene from the light, reflections a third; the skybox, lighting
  // and textures). Depth is the same either way.
  const bool colour = rgb != nullptr;
  scene_.flags[mjRND_SHADOW] = colour ? 1 : 0;
  scene_.flags[mjRND_REFLECTION] = colour ? 1 : 0;
  scene_.flags[mjRND_SKYBOX] = colour ? 1 : 0;
  scene_.flags[mjRND_SEGMENT] = colour ? 0 : 1;
  const mjrRect viewport{0, 0, width, height};
  mjr_render(viewport, &scene_, &render_context_);
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
    for (int y = 0; y < height; ++y) {
      const float* row = &depth_buffer_[static_cast<std::size_t>(height - 1 - y) * width];
      float* out = depth->data() + static_cast<std::size_t>(y) * width;
      for (int x = 0; x < width; ++x) {
        const double d = row[x];
        out[x] = d >= 1.0 ? 0.0f : static_cast<float>(near / (1.0 - d * (1.0 - near / far)));
      }
    }
  }
}

}  // namespace costar::sim
