// GLFW window context: an OpenGL 3.3 core profile window (forward compatible, double buffered, no
// MSAA in the window itself: the renderer resolves its own 4x samples and blits the frame in).
// Built by emscripten (app/web) the same code is the page's canvas: emscripten's GLFW over WebGL 2
// (OpenGL ES 3.0, GLSL ES 3.00), opaque, no MSAA of its own either.
#include "render/window_context.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <stdexcept>
#include <vector>

#include "render/gl_internal.h"

namespace dyn {
namespace {

std::string lastGlfwError() {
#ifdef __EMSCRIPTEN__
  return "this browser gave no WebGL 2 context";  // emscripten's GLFW has no glfwGetError
#else
  const char* what = nullptr;
  glfwGetError(&what);
  return what ? what : "unknown GLFW error";
#endif
}

class GlfwWindowContext final : public WindowContext {
 public:
  explicit GlfwWindowContext(const WindowOptions& o) {
    if (!glfwInit())
      throw std::runtime_error("cannot open a window: " + lastGlfwError() +
                               " (no display? run under xvfb-run -a, or set DISPLAY)");
#ifdef __EMSCRIPTEN__
    glfwWindowHint(GLFW_CLIENT_API, GLFW_OPENGL_ES_API);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 0);
    glfwWindowHint(GLFW_ALPHA_BITS, 0);  // an opaque canvas: the page behind never shows through
#else
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
#endif
    glfwWindowHint(GLFW_SAMPLES, 0);
    window_ = glfwCreateWindow(o.width, o.height, o.title.c_str(), nullptr, nullptr);
    if (!window_) {
      const std::string why = lastGlfwError();
      glfwTerminate();
      throw std::runtime_error("cannot open an OpenGL 3.3 core window: " + why);
    }
    glfwMakeContextCurrent(window_);
#ifndef __EMSCRIPTEN__
    glfwSwapInterval(o.vsync ? 1 : 0);  // the page's frames are the browser's (requestAnimationFrame)
#endif
    auto str = [](GLenum name) {
      const auto* s = reinterpret_cast<const char*>(glGetString(name));
      return std::string(s ? s : "?");
    };
    description_ = "GLFW " + std::string(glfwGetVersionString()) + ", " + str(GL_VERSION) + ", " +
                   str(GL_RENDERER);
  }
  ~GlfwWindowContext() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }

  int width() const override { return framebuffer().first; }
  int height() const override { return framebuffer().second; }
  std::string description() const override { return description_; }
#ifdef __EMSCRIPTEN__
  Glsl glsl() const override { return Glsl::Es300; }
#endif
  GLFWwindow* window() const override { return window_; }
  bool shouldClose() const override { return glfwWindowShouldClose(window_); }
  void pollEvents() override { glfwPollEvents(); }
  double seconds() const override { return glfwGetTime(); }
  void swap() override { glfwSwapBuffers(window_); }

  void clear(const Color& c) override {
    const auto [w, h] = framebuffer();
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, w, h);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClearColor(c.r, c.g, c.b, c.a);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  }

  Image screenshot() const override {
    const auto [w, h] = framebuffer();
    Image image;
    image.width = w;
    image.height = h;
    image.rgba.resize(std::size_t(w) * h * 4);
    std::vector<std::uint8_t> bottom_up(image.rgba.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
    const std::size_t row = std::size_t(w) * 4;
    for (int y = 0; y < h; ++y)
      std::copy_n(&bottom_up[std::size_t(h - 1 - y) * row], row, &image.rgba[std::size_t(y) * row]);
    for (std::size_t i = 3; i < image.rgba.size(); i += 4) image.rgba[i] = 255;  // a window is opaque
    return image;
  }

 private:
  std::pair<int, int> framebuffer() const {
    int w = 0, h = 0;
    glfwGetFramebufferSize(window_, &w, &h);
    return {w, h};
  }
  GLFWwindow* window_ = nullptr;
  std::string description_;
};

}  // namespace

std::unique_ptr<WindowContext> makeWindowContext(const WindowOptions& options) {
  return std::make_unique<GlfwWindowContext>(options);
}

}  // namespace dyn
