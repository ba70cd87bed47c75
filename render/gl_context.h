// GlContext: where frames are drawn. OSMesa offscreen (osmesa_context.cpp, no display) or a GLFW
// window (window_context.h, dynlab-ui); never both in one executable.
#pragma once
#include <memory>
#include <string>

namespace dyn {

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual std::string description() const = 0;  // e.g. "OSMesa 4.5 core, llvmpipe"
};

// Creates an offscreen OpenGL 3.3+ core context of the given size, current on this thread.
// Throws std::runtime_error with a readable message on failure. In dynlab_render_osmesa.
std::unique_ptr<GlContext> makeOffscreenContext(int width, int height);

}  // namespace dyn
