// Every registered lab's frames laid out around the overlay panel: at 640x480, 1280x720 and
// 1920x1080, with the panel (a short and a long title) and without it, the mechanism's own pixels
// never touch the panel and fill a good share of the rest of the frame. And the slider crank's
// reference marker x_d shows at 640x480 where x_d is.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "labs/run.h"
#include "render/framing.h"
#include "tests/render/test_scene.h"

using namespace dyn;
using dyn::test::inkBox;

namespace {


const char* const kLongTitle = "Lecture 7, direct force control on a closed chain: the default gains after one period";

}  // namespace

TEST_CASE("every lab's frames: the mechanism large in the frame and clear of the panel, at every size") {
  for (const LabEntry& entry : labRegistry()) {
    const LoadedLab loaded = loadLab(entry.name, "", "", 0.5);
    const Lab& lab = *loaded.lab;
    const Trace trace = runEngine(lab, Engine::Hand).trace;
    REQUIRE(trace.rows() > 2);
    const std::size_t row = trace.rows() / 2;
    for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 720}, std::pair{1920, 1080}}) {
      auto context = makeOffscreenContext(w, h);
      for (const char* panel : {"", "short", kLongTitle}) {
        // The frame as `dynlab run`/`figure` draw it (app/shared/movie.cpp renderRow).
        Scene scene;
        Overlay overlay;
        lab.scene(trace, row, nullptr, scene);
        lab.overlay(trace, row, overlay);
        if (*panel && std::string(panel) != "short") overlay.title = panel;
        RenderOptions o;
        o.show_overlay = *panel != '\0';
        Renderer renderer(*context, o);
        renderer.render(scene, &overlay);
        const PixelRect p = renderer.panelRect(), free = renderer.sceneRect();
        const std::vector<PixelRect> insets = renderer.insetRects();
        // The mechanism alone, through the camera the frame was drawn with (insets apart, checked
        // below); a clipped scene (a camera following across a floor) only where the frame keeps it:
        // the free part (tests/render/inset_test.cpp checks the cut).
        Scene alone = scene;
        alone.framing.fit = false;
        alone.camera = renderer.camera();
        alone.insets.clear();
        Image drawn = renderer.render(alone, nullptr);
        const Color& bg = scene.background;
        const std::uint8_t paper[3] = {std::uint8_t(std::lround(bg.r * 255)), std::uint8_t(std::lround(bg.g * 255)),
                                       std::uint8_t(std::lround(bg.b * 255))};
        if (scene.framing.clip)
          for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
              if (!(x >= std::ceil(free.x) && x < std::floor(free.right()) && y >= std::ceil(free.y) && y < std::floor(free.bottom())))
                std::copy_n(paper, 3, &drawn.rgba[(std::size_t(y) * w + x) * 4]);
        const PixelRect ink = inkBox(drawn, scene.background);
        // Insets: in the free part, clear of the panel.
        for (const PixelRect& r : insets) {
          CHECK_FALSE(r.intersects(p));
          CHECK(r.x >= free.x);
          CHECK(r.right() <= free.right());
          CHECK(r.y >= free.y);
          CHECK(r.bottom() <= free.bottom());
        }
        INFO("lab ", entry.name, " at ", w, "x", h, (*panel ? " with the panel" : " without the panel"), " (title ",
             overlay.title, "): panel ", p.x, ",", p.y, " ", p.w, "x", p.h, "; free ", free.x, ",", free.y, " ", free.w,
             "x", free.h, "; mechanism ", ink.x, ",", ink.y, " ", ink.w, "x", ink.h);
        CHECK_MESSAGE(scene.framing.fit, "a lab's scene asks the renderer to frame it (Scene::framing)");
        REQUIRE_FALSE(ink.empty());
        CHECK_FALSE(ink.intersects(p));
        // Large: as wide or as tall as the free part allows, and no fifth-of-the-frame speck.
        CHECK(std::max(ink.w / free.w, ink.h / free.h) > 0.75);
        CHECK(ink.w * ink.h / (free.w * free.h) > 0.2);
        CHECK(ink.w * ink.h > 0.12 * w * h);
        if (!*panel) {
          // Without the panel: the whole frame, the mechanism centred in it.
          CHECK(free.w == w);
          CHECK(std::abs(ink.x + 0.5 * ink.w - 0.5 * w) < 0.06 * w);
          CHECK(std::abs(ink.y + 0.5 * ink.h - 0.5 * h) < 0.06 * h);
        }
      }
    }
  }
}

TEST_CASE("slider crank at 640x480: the x_d marker shows, where x_d is, clear of the slider and the arrow") {
  const LoadedLab loaded = loadLab("slider_crank", "", "", 1.5);
  const Trace trace = runEngine(*loaded.lab, Engine::Hand).trace;
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  // Rows where x_c and x_d are close (the marker over the slider) and apart.
  for (std::size_t row : {std::size_t(100), std::size_t(750), std::size_t(1400)}) {
    Scene scene;
    Overlay overlay;
    loaded.lab->scene(trace, row, nullptr, scene);
    loaded.lab->overlay(trace, row, overlay);
    const Image image = renderer.render(scene, &overlay);
    const PixelRect panel = renderer.panelRect();
    // Green pixels (the marker's 0.20, 0.65, 0.30, lit) outside the panel, and where they are.
    long n = 0;
    double sum_x = 0;
    for (int y = 0; y < 480; ++y)
      for (int x = 0; x < 640; ++x) {
        if (x < panel.right() && y < panel.bottom()) continue;
        const std::uint8_t* p = image.pixel(x, y);
        if (p[1] > p[0] + 50 && p[1] > p[2] + 40) ++n, sum_x += x;
      }
    const double x_d = trace.at(row, "x_d");
    const Eigen::Vector2d at = Renderer::project(renderer.camera(), 640, 480, {x_d, 0, 0});
    INFO("row ", row, ": x_d = ", x_d, " at pixel ", at.x(), "; ", n, " green pixels, mean x ", n ? sum_x / n : -1);
    CHECK(n > 60);
    if (n > 0) CHECK(std::abs(sum_x / n - at.x()) < 2.0);
  }
}
