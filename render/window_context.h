// WindowContext: a GlContext that is a real window (GLFW, OpenGL 3.3 core through libGL/GLX), for
// the interactive tuning window. In dynlab_render_window, which must never be linked together
// with dynlab_render_osmesa (both bring the GL entry points).
#pragma once
#include <memory>
#include <string>

#include "labs/scene.h"
#include "render/gl_context.h"
#include "render/image.h"

struct GLFWwindow;

namespace dyn {

class WindowContext : public GlContext {
 public:
  // width()/height(): the window's framebuffer in pixels (changes when the window is resized).
  virtual GLFWwindow* window() const = 0;
  virtual bool shouldClose() const = 0;
  virtual void pollEvents() = 0;
  // Binds the window's framebuffer and clears all of it.
  virtual void clear(const Color& color) = 0;
  // Reads the back buffer (what the next swap() shows), top row first.
  virtual Image screenshot() const = 0;
  virtual void swap() = 0;
  virtual double seconds() const = 0;  // monotonic wall time
};

struct WindowOptions {
  int width = 1280, height = 720;  // window size in screen coordinates
  std::string title = "dynlab";
  bool vsync = true;               // off for scripted runs (as fast as possible)
};

// Opens the window and makes its context current on this thread. Throws std::runtime_error with a
// readable message (e.g. no display) on failure.
std::unique_ptr<WindowContext> makeWindowContext(const WindowOptions& options);

}  // namespace dyn
