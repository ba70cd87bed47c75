// Shared test helpers for render/: an offscreen context per test and small scenes.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <unistd.h>

#include "labs/scene.h"
#include "render/framing.h"
#include "render/gl_context.h"
#include "render/renderer.h"

namespace dyn::test {

// Whether an RGB pixel is within tolerance levels (0–255, per channel) of a scene colour.
inline bool nearColor(const std::uint8_t* p, const Color& c, int tolerance) {
  const float want[3] = {c.r, c.g, c.b};
  for (int i = 0; i < 3; ++i)
    if (std::abs(int(p[i]) - int(want[i] * 255.0f + 0.5f)) > tolerance) return false;
  return true;
}

// The pixel box of every pixel that is not the background colour (rows and columns inclusive).
inline PixelRect inkBox(const Image& image, const Color& bg) {
  int x0 = image.width, y0 = image.height, x1 = -1, y1 = -1;
  const int r = int(std::lround(bg.r * 255)), g = int(std::lround(bg.g * 255)), b = int(std::lround(bg.b * 255));
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      if (std::abs(p[0] - r) + std::abs(p[1] - g) + std::abs(p[2] - b) > 6)
        x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  if (x1 < 0) return {};
  return {double(x0), double(y0), double(x1 - x0 + 1), double(y1 - y0 + 1)};
}

// A single red capsule from (0,0,0) to (0.5,0.3,0), orthographic camera looking down -z.
inline Scene redCapsuleScene() {
  Scene scene;
  scene.capsules.push_back({{0, 0, 0}, {0.5, 0.3, 0}, 0.05, {0.85f, 0.1f, 0.1f, 1.0f}});
  scene.camera.half_height = 1.0;
  return scene;
}

inline Overlay sampleOverlay() {
  Overlay overlay;
  overlay.title = "render test";
  overlay.lines = {{"time", "1.250 s"}, {"energy", "3.1416 J"}};
  Series s{"q1", {}, {0.2f, 0.4f, 0.8f, 1.0f}};
  for (int i = 0; i < 60; ++i) s.values.push_back(float(i % 17) / 17.0f);
  overlay.plots.push_back(s);
  return overlay;
}

// A fresh file name under the system temp dir, unique per process.
inline std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("dynlab_render_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

}  // namespace dyn::test
