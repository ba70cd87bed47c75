// Framing (render/framing.h) and the mini-plots' y scale (render/plot_widget.h): a fitted camera
// puts the box centred in the free rectangle and fills it (ortho and perspective), one fitted to
// points (Scene::framing.points) fills it with what the points outline, not their box, the free
// rectangle is the side of the panel that shows the box larger, the renderer keeps a fitted scene
// clear of the panel, and the y scale's labels say how big a ripple is.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "render/framing.h"
#include "render/plot_widget.h"
#include "tests/render/test_scene.h"

using namespace dyn;
using dyn::test::inkBox;

namespace {

Eigen::AlignedBox3d box(Eigen::Vector3d lo, Eigen::Vector3d hi) { return Eigen::AlignedBox3d(lo, hi); }


}  // namespace

TEST_CASE("fitCamera centres the box in the free rectangle and fills it, ortho and perspective") {
  const Eigen::AlignedBox3d b = box({-0.2, -0.1, -0.05}, {1.1, 0.4, 0.05});
  const int w = 1280, h = 720;
  for (const PixelRect free : {PixelRect{300, 0, 980, 720}, PixelRect{0, 400, 1280, 320}, PixelRect{0, 0, 1280, 720}}) {
    for (bool ortho : {true, false}) {
      Camera cam;
      cam.ortho = ortho;
      cam.eye = {0.3, 0.4, 3};  // a view from the front, a little from above
      cam.target = {0, 0, 0};
      const Camera fitted = fitCamera(cam, b, w, h, free, 1.1);
      const PixelRect p = projectedBox(fitted, w, h, b);
      INFO("ortho ", ortho, " free ", free.x, ",", free.y, " ", free.w, "x", free.h, " -> box ", p.x, ",", p.y, " ",
           p.w, "x", p.h);
      // Inside, centred, and one side (the one that binds) filling it less the 10 % margin.
      CHECK(p.x >= free.x - 1e-6);
      CHECK(p.y >= free.y - 1e-6);
      CHECK(p.right() <= free.right() + 1e-6);
      CHECK(p.bottom() <= free.bottom() + 1e-6);
      CHECK(p.x + 0.5 * p.w == doctest::Approx(free.x + 0.5 * free.w).epsilon(1e-3));
      CHECK(p.y + 0.5 * p.h == doctest::Approx(free.y + 0.5 * free.h).epsilon(1e-3));
      CHECK(std::max(p.w / free.w, p.h / free.h) == doctest::Approx(1 / 1.1).epsilon(1e-3));
      // The view direction is kept.
      CHECK((fitted.eye - fitted.target).normalized().isApprox((cam.eye - cam.target).normalized(), 1e-9));
    }
  }
}

TEST_CASE("fitCamera on points: a box's corners give the box's camera; a slanted rod fills the frame, its box does not") {
  const int w = 640, h = 480;
  const PixelRect free{0, 0, 640, 480};
  Camera cam;
  cam.ortho = false;
  cam.fov_y_deg = 35;
  cam.up = {0, 0, 1};
  cam.target = {0, 0, 0};
  cam.eye = {0.5, -1.2, 0.55};  // the model pictures' view: from the front, a little from above
  // A box's eight corners as points: the very camera fitCamera(box) places.
  const Eigen::AlignedBox3d b = box({-0.2, -0.1, 0}, {0.6, 0.3, 0.9});
  std::vector<Eigen::Vector3d> corners;
  for (int k = 0; k < 8; ++k) corners.push_back(b.corner(Eigen::AlignedBox3d::CornerType(k)));
  const Camera by_box = fitCamera(cam, b, w, h, free, 1.08), by_points = fitCamera(cam, corners, w, h, free, 1.08);
  CHECK(by_box.eye == by_points.eye);
  CHECK(by_box.target == by_points.target);
  // A rod across the box's diagonal (a robot reaching out over its base): fitted by its points it
  // fills the frame; fitted by its box, whose corners stand far out of it seen at an angle, it does not.
  std::vector<Eigen::Vector3d> rod;
  for (int k = 0; k <= 10; ++k) rod.push_back(b.min() + 0.1 * k * (b.max() - b.min()));
  const PixelRect fill = projectedPoints(fitCamera(cam, rod, w, h, free, 1.08), w, h, rod);
  const PixelRect loose = projectedPoints(fitCamera(cam, b, w, h, free, 1.08), w, h, rod);
  INFO("points ", fill.w, "x", fill.h, "; box ", loose.w, "x", loose.h);
  CHECK(fill.x >= -1e-6);
  CHECK(fill.right() <= w + 1e-6);
  CHECK(fill.y >= -1e-6);
  CHECK(fill.bottom() <= h + 1e-6);
  CHECK(std::max(fill.w / w, fill.h / h) == doctest::Approx(1 / 1.08).epsilon(1e-3));
  CHECK(std::max(loose.w / w, loose.h / h) < 0.85);
}

TEST_CASE("freeRect: the whole frame without a panel, else beside or below it, whichever shows the box larger") {
  Camera cam;
  const PixelRect panel{10, 10, 260, 290};
  const PixelRect whole = freeRect(640, 480, {}, cam, box({0, 0, 0}, {1, 1, 0}), 10);
  CHECK(whole.w == 640);
  CHECK(whole.h == 480);
  // A tall box goes beside the panel, a wide flat one below it.
  const PixelRect tall = freeRect(640, 480, panel, cam, box({0, 0, 0}, {0.3, 1, 0}), 10);
  CHECK(tall.x == 280);
  CHECK(tall.h == 480);
  const PixelRect wide = freeRect(640, 480, panel, cam, box({0, 0, 0}, {3, 0.5, 0}), 10);
  CHECK(wide.y == 310);
  CHECK(wide.w == 640);
  CHECK_FALSE(tall.intersects(panel));
  CHECK_FALSE(wide.intersects(panel));
}

TEST_CASE("sceneBounds holds every primitive with its radius") {
  Scene s;
  s.capsules.push_back({{0, 0, 0}, {1, 0, 0}, 0.1, {}});
  s.arrows.push_back({{1, 0, 0}, {0, -0.5, 0}, 0.01, {}});
  s.polylines.push_back({{{-0.3, 0.2, 0}, {0, 0.7, 0}}, 2, {}});
  const Eigen::AlignedBox3d b = sceneBounds(s);
  CHECK(b.min().x() == doctest::Approx(-0.3));
  CHECK(b.max().x() == doctest::Approx(1.1));
  CHECK(b.min().y() == doctest::Approx(-0.522));
  CHECK(b.max().y() == doctest::Approx(0.7));
  CHECK(sceneBounds(Scene{}).isEmpty());
}

TEST_CASE("a fitted scene is drawn large in the part of the frame the panel leaves free, and never under it") {
  Scene scene = test::redCapsuleScene();
  scene.camera.half_height = 20;  // as given, the capsule would be a speck: the fit must override it
  scene.framing.fit = true;
  Overlay overlay = test::sampleOverlay();
  for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 720}, std::pair{1920, 1080}}) {
    for (bool panel : {true, false}) {
      for (const char* title : {"short", "a very long title, as a lecturer gives a slide: Lecture 7, force control"}) {
        overlay.title = title;
        auto context = makeOffscreenContext(w, h);
        RenderOptions o;
        o.show_overlay = panel;
        Renderer renderer(*context, o);
        renderer.render(scene, &overlay);
        const PixelRect free = renderer.sceneRect(), p = renderer.panelRect();
        // The same scene through the same camera, without the panel: the mechanism's own pixels.
        Scene alone = scene;
        alone.framing.fit = false;
        alone.camera = renderer.camera();
        const PixelRect ink = inkBox(renderer.render(alone, nullptr), scene.background);
        INFO(w, "x", h, " panel ", panel, " title ", title, ": panel ", p.x, ",", p.y, " ", p.w, "x", p.h, "; free ",
             free.x, ",", free.y, " ", free.w, "x", free.h, "; drawn ", ink.x, ",", ink.y, " ", ink.w, "x", ink.h);
        REQUIRE_FALSE(ink.empty());
        CHECK(p.empty() != panel);
        CHECK_FALSE(ink.intersects(p));
        // Large: one side fills the free rectangle (less the margin); a good share of its area.
        CHECK(std::max(ink.w / free.w, ink.h / free.h) > 0.85);
        CHECK(ink.w * ink.h / (free.w * free.h) > 0.3);
        // The panel never takes more than 40 % of the width, however long the title.
        CHECK(p.right() <= 0.4 * w + 2 * 10 * std::floor(h / 480.0 + 0.2) + 1);
        if (!panel) CHECK(free.w * free.h == doctest::Approx(double(w) * h));
      }
    }
  }
}

TEST_CASE("a scene that does not ask to be fitted keeps its own camera") {
  const Scene scene = test::redCapsuleScene();
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  renderer.render(scene, nullptr);
  CHECK(renderer.camera().eye == scene.camera.eye);
  CHECK(renderer.camera().half_height == scene.camera.half_height);
}

TEST_CASE("the y scale: round bounds around the data, labels that tell a ripple from a swing") {
  // A ±0.03 N ripple about -5 N: labelled as such, and the range no wider than the ripple needs.
  const PlotScale ripple = plotScale(-5.03, -4.97);
  CHECK(ripple.top == "-4.97");
  CHECK(ripple.bottom == "-5.03");
  CHECK(ripple.lo <= -5.03);
  CHECK(ripple.hi >= -4.97);
  CHECK(ripple.hi - ripple.lo < 1.5 * 0.06);
  // A swing of tens of millimetres: whole numbers.
  const PlotScale swing = plotScale(-41.09, 29.7);
  CHECK(swing.top == "30");
  CHECK(swing.bottom == "-50");
  // Tiny values keep their exponent; labels always differ; no "-0".
  const PlotScale tiny = plotScale(1e-15, 1.3e-14);
  CHECK(tiny.top != tiny.bottom);
  CHECK(tiny.top.find('e') != std::string::npos);
  CHECK(plotScale(-0.2, -0.001).top == "0");  // ceil(-0.02) is -0: written "0", not "-0.00"
  // A flat series gets a range around its value; non-finite input a default range.
  const PlotScale flat = plotScale(-5, -5);
  CHECK(flat.lo < -5);
  CHECK(flat.hi > -5);
  CHECK(flat.top != flat.bottom);
  CHECK(plotScale(NAN, 1).hi > plotScale(NAN, 1).lo);
}

TEST_CASE("a mini-plot's labels are drawn: the panel with a ripple and with a swing differ beside the plot") {
  // The same curve shape at two scales: without labels the panels would be identical.
  Overlay a = test::sampleOverlay(), b = test::sampleOverlay();
  for (float& v : a.plots[0].values) v = -5.0f + 0.06f * v;
  for (float& v : b.plots[0].values) v = -50.0f + 60.0f * v;
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  const Scene scene = test::redCapsuleScene();
  const Image ia = renderer.render(scene, &a), ib = renderer.render(scene, &b);
  const PixelRect p = renderer.panelRect();
  // Compare the left 60 px of the panel's lower part, where the plot's gutter is.
  long differing = 0;
  for (int y = int(p.y + 0.5 * p.h); y < int(p.bottom()); ++y)
    for (int x = int(p.x); x < int(p.x + 60); ++x) differing += ia.pixel(x, y)[0] != ib.pixel(x, y)[0];
  CHECK(differing > 20);
}
