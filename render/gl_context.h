// GlContext: where frames are drawn. OSMesa (offscreen, no display) today; a window later.
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
// Throws std::runtime_error with a readable message on failure.
std::unique_ptr<GlContext> makeOffscreenContext(int width, int height);

}  // namespace dyn
