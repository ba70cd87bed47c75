// Shared test helpers for render/: an offscreen context per test and small scenes.
#pragma once
#include <filesystem>
#include <string>
#include <unistd.h>

#include "labs/scene.h"
#include "render/gl_context.h"
#include "render/renderer.h"

namespace dyn::test {

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
