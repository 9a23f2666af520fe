#pragma once
// Where the viewer draws: a GLFW window (OpenGL 3.3 core, 4x multisampled), or, headless, an
// EGL surfaceless context on Mesa with an offscreen multisampled framebuffer, which needs no
// display at all. Both give the same drawing target to the renderer and read the last frame
// back as RGB pixels for screenshots.

#include <memory>
#include <string>

#include "mm/runtime/result.hpp"
#include "run_plot.hpp"

struct GLFWwindow;

namespace mm::viewer {

class GlContext {
 public:
  // A window of this size (GLFW: fails without a display, with GLFW's message).
  static Result<std::unique_ptr<GlContext>> create_window(int width, int height,
                                                          const std::string& title);
  // An offscreen context and framebuffer of this size (EGL surfaceless).
  static Result<std::unique_ptr<GlContext>> create_headless(int width, int height);
  virtual ~GlContext() = default;

  // The window (null when headless).
  virtual GLFWwindow* window() const = 0;
  // The framebuffer to draw into and its size in pixels (a window's may change).
  virtual unsigned framebuffer() const = 0;
  virtual void framebuffer_size(int& width, int& height) const = 0;
  // Ends a frame: swaps a window's buffers; resolves the offscreen multisampling.
  virtual void present() = 0;
  // The frame just drawn (call before present() for a window, after it when headless).
  virtual Image read_pixels() const = 0;
};

}  // namespace mm::viewer
