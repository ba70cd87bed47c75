// GlContext: where frames are drawn. OSMesa offscreen (osmesa_context.cpp, no display), a GLFW
// window (window_context.h, dynlab-ui), or a WebGL 2 canvas (the same window_context.cpp built by
// emscripten, app/web); never two in one executable. The context says which GLSL its shaders are in.
#pragma once
#include <memory>
#include <string>

namespace dyn {

// The shading language the context compiles: GLSL 3.30 core (desktop GL 3.3+, OSMesa) or GLSL ES 3.00
// (OpenGL ES 3.0 / WebGL 2). The renderer's programs are one text with this header before it.
enum class Glsl { Core330, Es300 };
// "#version 330 core\n", or "#version 300 es\nprecision highp float;\n" (ES has no default float
// precision in fragment shaders).
const char* glslHeader(Glsl dialect);
// The version line alone, as Dear ImGui's OpenGL3 backend takes it ("#version 330 core").
const char* glslVersion(Glsl dialect);

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual int width() const = 0;
  virtual int height() const = 0;
  virtual std::string description() const = 0;  // e.g. "OSMesa 4.5 core, llvmpipe"
  virtual Glsl glsl() const { return Glsl::Core330; }
};

// Creates an offscreen OpenGL 3.3+ core context of the given size, current on this thread.
// Throws std::runtime_error with a readable message on failure. In dynlab_render_osmesa.
std::unique_ptr<GlContext> makeOffscreenContext(int width, int height);

}  // namespace dyn
