#include "gl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLFW/glfw3.h>

#include <cstring>

#include "gl.hpp"

namespace mm::viewer {
namespace {

// Rows come out of OpenGL bottom first; images are stored top first.
Image read_framebuffer(unsigned framebuffer, int width, int height) {
  Image out;
  out.width = width;
  out.height = height;
  out.rgb.resize(static_cast<size_t>(width) * height * 3);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, out.rgb.data());
  const size_t row = static_cast<size_t>(width) * 3;
  std::vector<unsigned char> swap(row);
  for (int y = 0; y < height / 2; ++y) {
    unsigned char* a = out.rgb.data() + row * y;
    unsigned char* b = out.rgb.data() + row * (height - 1 - y);
    std::memcpy(swap.data(), a, row);
    std::memcpy(a, b, row);
    std::memcpy(b, swap.data(), row);
  }
  return out;
}

// ---- A GLFW window.

std::string glfw_error() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown GLFW error";
}

class WindowContext final : public GlContext {
 public:
  explicit WindowContext(GLFWwindow* window) : window_(window) {}
  ~WindowContext() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  GLFWwindow* window() const override { return window_; }
  unsigned framebuffer() const override { return 0; }
  void framebuffer_size(int& width, int& height) const override {
    glfwGetFramebufferSize(window_, &width, &height);
  }
  void present() override { glfwSwapBuffers(window_); }
  Image read_pixels() const override {
    int width = 0, height = 0;
    framebuffer_size(width, height);
    glReadBuffer(GL_BACK);
    return read_framebuffer(0, width, height);
  }

 private:
  GLFWwindow* window_;
};

// ---- EGL surfaceless, drawing into a multisampled framebuffer resolved on present().

class HeadlessContext final : public GlContext {
 public:
  HeadlessContext(EGLDisplay display, EGLContext context) : display_(display), context_(context) {}
  ~HeadlessContext() override {
    glDeleteFramebuffers(2, framebuffers_);
    glDeleteRenderbuffers(3, renderbuffers_);
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }

  Status create_framebuffers(int width, int height) {
    width_ = width;
    height_ = height;
    glGenFramebuffers(2, framebuffers_);
    glGenRenderbuffers(3, renderbuffers_);
    const int samples = 4;
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[0]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[1]);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH24_STENCIL8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffers_[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              renderbuffers_[0]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                              renderbuffers_[1]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"headless: the multisampled framebuffer is incomplete"};
    }
    glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[2]);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffers_[1]);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                              renderbuffers_[2]);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      return Error{"headless: the resolve framebuffer is incomplete"};
    }
    return Status::success();
  }

  GLFWwindow* window() const override { return nullptr; }
  unsigned framebuffer() const override { return framebuffers_[0]; }
  void framebuffer_size(int& width, int& height) const override {
    width = width_;
    height = height_;
  }
  void present() override {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, framebuffers_[0]);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffers_[1]);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT,
                      GL_NEAREST);
    glFinish();
  }
  Image read_pixels() const override { return read_framebuffer(framebuffers_[1], width_, height_); }

 private:
  EGLDisplay display_;
  EGLContext context_;
  int width_ = 0;
  int height_ = 0;
  GLuint framebuffers_[2] = {0, 0};      // multisampled, resolved
  GLuint renderbuffers_[3] = {0, 0, 0};  // colour, depth (multisampled), resolved colour
};

Result<EGLDisplay> open_surfaceless_display() {
  auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display) return Error{"headless: EGL has no eglGetPlatformDisplayEXT"};
  EGLDisplay display =
      get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) {
    return Error{"headless: no EGL surfaceless display (Mesa's EGL_MESA_platform_surfaceless)"};
  }
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) {
    return Error{"headless: eglInitialize failed (error 0x" + std::to_string(eglGetError()) + ")"};
  }
  return display;
}

}  // namespace

Result<std::unique_ptr<GlContext>> GlContext::create_window(int width, int height,
                                                            const std::string& title) {
  if (!glfwInit()) return Error{"window: " + glfw_error()};
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 4);
  GLFWwindow* window = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window) {
    std::string message = "window: " + glfw_error();
    glfwTerminate();
    return Error{message};
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  return std::unique_ptr<GlContext>(new WindowContext(window));
}

Result<std::unique_ptr<GlContext>> GlContext::create_headless(int width, int height) {
  Result<EGLDisplay> display = open_surfaceless_display();
  if (!display) return display.error();
  // The surfaceless platform offers pbuffer configurations only (the default asks for windows).
  const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                      EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint config_count = 0;
  if (!eglChooseConfig(*display, config_attributes, &config, 1, &config_count) ||
      config_count == 0 || !eglBindAPI(EGL_OPENGL_API)) {
    eglTerminate(*display);
    return Error{"headless: no EGL configuration for desktop OpenGL"};
  }
  const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION,
                                       3,
                                       EGL_CONTEXT_MINOR_VERSION,
                                       3,
                                       EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                       EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                       EGL_NONE};
  EGLContext context = eglCreateContext(*display, config, EGL_NO_CONTEXT, context_attributes);
  if (context == EGL_NO_CONTEXT ||
      !eglMakeCurrent(*display, EGL_NO_SURFACE, EGL_NO_SURFACE, context)) {
    if (context != EGL_NO_CONTEXT) eglDestroyContext(*display, context);
    eglTerminate(*display);
    return Error{"headless: cannot make an OpenGL 3.3 core context current"};
  }
  auto headless = std::make_unique<HeadlessContext>(*display, context);
  if (Status s = headless->create_framebuffers(width, height); !s) return Error{s.message()};
  return std::unique_ptr<GlContext>(std::move(headless));
}

}  // namespace mm::viewer
