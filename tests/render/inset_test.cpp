// Insets and clipped scenes (labs/scene.h Inset, Framing::clip): an inset goes in a corner of the
// part of the frame the main scene was fitted into, inside its border, with its own camera; a
// clipped scene never draws under the panel. And the unicycle's frames use both: a camera that
// follows the wheel (large, the leader beside it) and a map of the whole course in a corner.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "labs/run.h"
#include "labs/unicycle/lab.h"
#include "render/framing.h"
#include "tests/render/test_scene.h"

using namespace dyn;
using dyn::test::inkBox;

namespace {

bool inside(const PixelRect& outer, const PixelRect& r) {
  return r.x >= outer.x - 1e-9 && r.y >= outer.y - 1e-9 && r.right() <= outer.right() + 1e-9 &&
         r.bottom() <= outer.bottom() + 1e-9;
}

bool near(const std::uint8_t* p, int r, int g, int b, int tol = 12) {
  return std::abs(p[0] - r) + std::abs(p[1] - g) + std::abs(p[2] - b) <= tol;
}

// A floor much larger than the part of it the camera is fitted to (a follow camera), clipped.
Scene floorScene() {
  Scene s;
  s.planes.push_back({{0, 0, 0}, Eigen::Matrix3d::Identity(), {20, 20}, {0.3f, 0.5f, 0.3f, 1.0f}, 0.0, 1.0});
  s.spheres.push_back({{0, 0, 0.1}, 0.1, {0.85f, 0.1f, 0.1f, 1.0f}});
  s.framePerspective(Eigen::AlignedBox3d(Eigen::Vector3d(-0.5, -0.5, 0), Eigen::Vector3d(0.5, 0.5, 0.2)),
                     Eigen::Vector3d(0, -0.8, 1.0));
  return s;
}

}  // namespace

TEST_CASE("insetRect: its corner of the free part, gap pixels in, height share and aspect, whole pixels") {
  const PixelRect free{300, 0, 500, 480};
  Inset inset;
  inset.height = 0.35, inset.aspect = 1.25, inset.gap = 6;
  for (auto corner : {Inset::Corner::TopRight, Inset::Corner::BottomRight, Inset::Corner::BottomLeft, Inset::Corner::TopLeft}) {
    inset.corner = corner;
    const PixelRect r = insetRect(free, inset);
    INFO("corner ", int(corner), ": ", r.x, ",", r.y, " ", r.w, "x", r.h);
    CHECK(inside(free, r));
    CHECK(r.h == std::round(0.35 * 480));
    CHECK(r.w == std::round(r.h * 1.25));
    CHECK(r.x == std::round(r.x));
    const bool right = corner == Inset::Corner::TopRight || corner == Inset::Corner::BottomRight;
    const bool bottom = corner == Inset::Corner::BottomRight || corner == Inset::Corner::BottomLeft;
    CHECK((right ? free.right() - r.right() : r.x - free.x) == doctest::Approx(6));
    CHECK((bottom ? free.bottom() - r.bottom() : r.y - free.y) == doctest::Approx(6));
  }
  // At most half the free width, however wide its aspect asks.
  inset.aspect = 5;
  CHECK(insetRect(free, inset).w == 250);
}

TEST_CASE("a clipped scene stays out of the panel's side; an inset is drawn in its rectangle, with its own camera") {
  for (auto [w, h] : {std::pair{640, 480}, std::pair{1280, 720}}) {
    auto context = makeOffscreenContext(w, h);
    Renderer renderer(*context);
    Overlay overlay = test::sampleOverlay();
    Scene scene = floorScene();
    // Unclipped, the floor runs under the panel; clipped, only the free part has it.
    const Image spill = renderer.render(scene, &overlay);
    scene.framing.clip = true;
    Inset inset;
    inset.corner = Inset::Corner::BottomRight;
    inset.scene.background = {1, 1, 1, 1};
    inset.scene.spheres.push_back({{5, 5, 0}, 0.5, {0.1f, 0.2f, 0.9f, 1.0f}});
    inset.scene.camera.half_height = 100;  // a speck as given: the inset's own framing fits it
    inset.scene.framing.fit = true;
    scene.insets.push_back(inset);
    const Image image = renderer.render(scene, &overlay);
    const PixelRect p = renderer.panelRect(), free = renderer.sceneRect();
    INFO(w, "x", h, ": panel ", p.x, ",", p.y, " ", p.w, "x", p.h, "; free ", free.x, ",", free.y, " ", free.w, "x", free.h);
    REQUIRE_FALSE(p.empty());
    const Color& bg = scene.background;
    const int br = int(std::lround(bg.r * 255)), bgg = int(std::lround(bg.g * 255)), bb = int(std::lround(bg.b * 255));
    // Outside the free part and the panel: background when clipped (floor when not).
    long outside = 0, clean = 0, spilt = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const bool in_free = x >= free.x && x < free.right() && y >= free.y && y < free.bottom();
        const bool in_panel = x < p.right() + 1 && y < p.bottom() + 1;
        if (in_free || in_panel) continue;
        ++outside;
        clean += near(image.pixel(x, y), br, bgg, bb, 6);

        spilt += !near(spill.pixel(x, y), br, bgg, bb, 6);
      }
    REQUIRE(outside > 1000);
    CHECK(clean == outside);
    CHECK(spilt > outside / 2);  // without the clip, the same floor does spill there
    // The inset: in the free part's bottom-right corner, bordered, its sphere fitted in and centred.
    REQUIRE(renderer.insetRects().size() == 1);
    const PixelRect r = renderer.insetRects()[0];
    CHECK(inside(free, r));
    CHECK_FALSE(r.intersects(p));
    CHECK(near(image.pixel(int(r.x) - 1, int(r.y + r.h / 2)), 89, 89, 97));  // the border's grey
    const Camera& cam = renderer.insetCameras()[0];
    const Eigen::Vector2d c = Renderer::project(cam, int(r.w), int(r.h), {5, 5, 0});
    CHECK(c.x() == doctest::Approx(r.w / 2).epsilon(0.02));
    CHECK(c.y() == doctest::Approx(r.h / 2).epsilon(0.02));
    long blue = 0;
    for (int y = int(r.y); y < int(r.bottom()); ++y)
      for (int x = int(r.x); x < int(r.right()); ++x) {
        const std::uint8_t* q = image.pixel(x, y);
        blue += q[2] > q[0] + 60 && q[2] > q[1] + 40;
      }
    CHECK(blue > 0.3 * r.w * r.h);  // the sphere fills the inset (a speck without its framing)
  }
}

TEST_CASE("unicycle at 640x480: the wheel large where it is, the leader in the frame, the course in the map") {
  const LoadedLab loaded = loadLab("unicycle", "", "", 3.0);
  const Lab& lab = *loaded.lab;
  const Trace trace = runEngine(lab, Engine::Hand).trace;
  const Trace ghost = runEngine(lab, Engine::Bullet).trace;
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  for (double t : {0.0, 1.0, 2.0, 2.9}) {
    const std::size_t row = std::min(trace.rows() - 1, std::size_t(std::lround(t / lab.dt())));
    Scene scene;
    Overlay overlay;
    lab.scene(trace, row, &ghost, scene);
    lab.overlay(trace, row, overlay);
    const Image image = renderer.render(scene, &overlay);
    const PixelRect p = renderer.panelRect(), free = renderer.sceneRect();
    REQUIRE(renderer.insetRects().size() == 1);
    const PixelRect map = renderer.insetRects()[0];
    // The wheel's rim, projected: a disk of radius r standing at (x, y), heading phi.
    const double r = 0.1, x = trace.at(row, "x"), y = trace.at(row, "y"), phi = trace.at(row, "phi");
    const Eigen::Vector3d centre(x, y, r), ahead(std::cos(phi), std::sin(phi), 0), up(0, 0, 1);
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (int k = 0; k < 64; ++k) {
      const double a = 2 * M_PI * k / 64;
      const Eigen::Vector2d q = Renderer::project(renderer.camera(), 640, 480, centre + r * (std::cos(a) * ahead + std::sin(a) * up));
      x0 = std::min(x0, q.x()), x1 = std::max(x1, q.x()), y0 = std::min(y0, q.y()), y1 = std::max(y1, q.y());
    }
    // The wheel's blue (0.23, 0.42, 0.68, lit) within its rim's box, outside panel and map.
    long wheel = 0;
    for (int py = std::max(0, int(y0) - 2); py <= std::min(479, int(y1) + 2); ++py)
      for (int px = std::max(0, int(x0) - 2); px <= std::min(639, int(x1) + 2); ++px) {
        if ((px < p.right() && py < p.bottom()) || (px >= map.x && px < map.right() && py >= map.y && py < map.bottom())) continue;
        const std::uint8_t* q = image.pixel(px, py);
        wheel += q[2] > q[0] + 25 && q[2] > q[1];  // lit or in shade
      }
    const Eigen::Vector2d leader = Renderer::project(renderer.camera(), 640, 480, {trace.at(row, "x_d"), trace.at(row, "y_d"), 0.06});
    INFO("t = ", t, ": rim box ", x0, "..", x1, " x ", y0, "..", y1, ", ", wheel, " wheel pixels; leader at ", leader.x(), ",",
         leader.y(), "; free ", free.x, ",", free.y, " ", free.w, "x", free.h, "; map ", map.x, ",", map.y, " ", map.w, "x", map.h);
    // Large: at least 50 px across (the whole-course view drew it about 18 px), and inked with its
    // blue over more than twice the pixels an 18 px disk has (the leader, translucent, may stand
    // in front of it).
    CHECK(std::max(x1 - x0, y1 - y0) >= 50);
    CHECK(wheel >= 600);
    // The wheel and the leader in the free part, clear of the panel and of the map.
    CHECK(x0 >= free.x);
    CHECK(x1 <= free.right());
    CHECK(leader.x() >= free.x);
    CHECK(leader.x() <= free.right());
    CHECK(leader.y() >= free.y);
    CHECK(leader.y() <= free.bottom());
    CHECK_FALSE(map.intersects(PixelRect{leader.x() - 3, leader.y() - 3, 6, 6}));
    CHECK_FALSE(map.intersects(PixelRect{x0, y0, x1 - x0, y1 - y0}));
    // The map shows the whole course: every point of the path inside it.
    const Camera& mc = renderer.insetCameras()[0];
    const auto& course = static_cast<const unicycle::UnicycleLab&>(lab).path().polyline();
    for (const auto& pt : course) {
      const Eigen::Vector2d q = Renderer::project(mc, int(map.w), int(map.h), {pt.x(), pt.y(), 0});
      CHECK(q.x() >= 0);
      CHECK(q.x() <= map.w);
      CHECK(q.y() >= 0);
      CHECK(q.y() <= map.h);
    }
  }
}
