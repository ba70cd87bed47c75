// Tests for the primitives labs use beyond capsules and boxes: cylinders with spokes, planes
// with paths on them, friction cones, springs, and perspective framing of 3-D scenes. With
// DYNLAB_RENDER_DEMO_DIR set, also writes the demo scenes as PNGs there (to look at them).
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>

#include "render/image.h"
#include "tests/render/demo_scenes.h"
#include "tests/render/test_scene.h"

using namespace dyn;

TEST_CASE("demo scenes are written as PNGs when DYNLAB_RENDER_DEMO_DIR is set") {
  const char* dir = std::getenv("DYNLAB_RENDER_DEMO_DIR");
  if (!dir) return;
  std::filesystem::create_directories(dir);
  auto write = [&](const std::string& name, const Scene& scene, int w, int h) {
    auto context = makeOffscreenContext(w, h);
    Renderer renderer(*context);
    CHECK(writePng(std::string(dir) + "/" + name + ".png", renderer.render(scene, nullptr)));
  };
  write("pen_on_table", test::penOnTableScene(), 640, 480);
  write("pen_on_table_wide", test::penOnTableScene({}, 16.0 / 9.0), 960, 540);
  // Close up, from low over the table: the ink's pen-lift gap, and no z-fighting at a grazing angle.
  Scene close = test::penOnTableScene();
  close.camera.lookAtBox({-0.12, -0.12, 0}, {0.22, 0.22, 0.02}, {0.2, -1.0, 0.18}, 4.0 / 3.0);
  write("pen_closeup_grazing", close, 640, 480);
  write("wheel", test::wheelScene(), 640, 480);
  write("grasp", test::graspScene(), 640, 480);
  write("spring", test::springScene(), 640, 300);
}
