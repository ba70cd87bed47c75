// OSMesa offscreen context: an OpenGL 3.3+ core profile context (llvmpipe) rendering into a
// client-memory RGBA buffer; no display, no GPU needed.
#include <GL/osmesa.h>

#include <exception>
#include <stdexcept>
#include <vector>

#include "render/gl_context.h"

namespace dyn {
namespace {

class OsmesaContext final : public GlContext {
 public:
  OsmesaContext(int width, int height) : width_(width), height_(height) {
    if (width <= 0 || height <= 0)
      throw std::runtime_error("OSMesa: invalid size " + std::to_string(width) + "x" +
                               std::to_string(height));
    // Core profile 3.3 or newer; depth lives in our own framebuffers, so the buffer needs none.
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           24,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           3,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           3,
                           0};
    context_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!context_)
      throw std::runtime_error("OSMesa: could not create an OpenGL 3.3 core context");
    buffer_.resize(std::size_t(width) * height * 4);  // std::bad_alloc: the context left to the process's end, as below
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, width, height)) {
      OSMesaDestroyContext(context_);
      throw std::runtime_error("OSMesa: could not make the context current");
    }
    // Describe what we got, e.g. "OSMesa 4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)".
    auto str = [](GLenum name) {
      const auto* s = reinterpret_cast<const char*>(glGetString(name));
      return std::string(s ? s : "?");
    };
    description_ = "OSMesa " + str(GL_VERSION) + ", " + str(GL_RENDERER);
  }
  // Destroyed while an exception unwinds (an allocation failed while drawing, out of memory), llvmpipe's
  // state may be half-built, and tearing it down crashed (SIGSEGV) instead of letting the error reach
  // its one line: then the context is left to the process's end.
  ~OsmesaContext() override {
    if (std::uncaught_exceptions() == 0) OSMesaDestroyContext(context_);
  }

  int width() const override { return width_; }
  int height() const override { return height_; }
  std::string description() const override { return description_; }

 private:
  int width_, height_;
  OSMesaContext context_ = nullptr;
  std::vector<unsigned char> buffer_;  // the default framebuffer's memory
  std::string description_;
};

}  // namespace

std::unique_ptr<GlContext> makeOffscreenContext(int width, int height) {
  return std::make_unique<OsmesaContext>(width, height);
}

}  // namespace dyn
