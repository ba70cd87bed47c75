// Renderer tests: the capsule is drawn where Renderer::project says, frames are reproducible,
// and the overlay panel shows up in the top-left corner from the very first frame.
#include <doctest/doctest.h>

#include <cstdlib>

#include "tests/render/test_scene.h"

using namespace dyn;

namespace {

bool reddish(const std::uint8_t* p) { return p[0] > 150 && p[1] < 90 && p[2] < 90; }

// The background exactly (2 levels: rounding).
bool isBackground(const std::uint8_t* p, const Color& bg) { return test::nearColor(p, bg, 2); }

}  // namespace

TEST_CASE("a red capsule is drawn where project() says, and nowhere else") {
  auto context = makeOffscreenContext(320, 240);
  CHECK(context->description().find("OSMesa") != std::string::npos);
  Renderer renderer(*context);
  const Scene scene = test::redCapsuleScene();
  const Image image = renderer.render(scene, nullptr);
  REQUIRE(image.width == 320);
  REQUIRE(image.height == 240);
  REQUIRE(image.rgba.size() == 320u * 240u * 4u);

  // Midpoint and points along the axis are red.
  for (double t : {0.1, 0.5, 0.9}) {
    const Eigen::Vector2d px =
        Renderer::project(scene.camera, 320, 240, t * Eigen::Vector3d(0.5, 0.3, 0));
    INFO("t=" << t << " px=" << px.transpose());
    CHECK(reddish(image.pixel(int(px.x()), int(px.y()))));
  }
  // The origin projects to the image centre under an orthographic camera at the origin.
  const Eigen::Vector2d centre = Renderer::project(scene.camera, 320, 240, Eigen::Vector3d::Zero());
  CHECK(centre.x() == doctest::Approx(160.0));
  CHECK(centre.y() == doctest::Approx(120.0));
  // +y world is up in the picture: p1 (y=0.3) lands above the centre.
  CHECK(Renderer::project(scene.camera, 320, 240, {0.5, 0.3, 0}).y() < 120.0);

  // Far from the capsule: exactly the background.
  for (const Eigen::Vector3d& w :
       {Eigen::Vector3d(-0.8, -0.8, 0), Eigen::Vector3d(0.8, -0.5, 0), Eigen::Vector3d(-0.5, 0.7, 0)}) {
    const Eigen::Vector2d px = Renderer::project(scene.camera, 320, 240, w);
    CHECK(isBackground(image.pixel(int(px.x()), int(px.y())), scene.background));
  }
  // Just beyond the radius (perpendicular to the axis) is background too.
  const Eigen::Vector3d mid(0.25, 0.15, 0), normal = Eigen::Vector3d(-0.3, 0.5, 0).normalized();
  const Eigen::Vector2d off = Renderer::project(scene.camera, 320, 240, mid + 0.08 * normal);
  CHECK(isBackground(image.pixel(int(off.x()), int(off.y())), scene.background));
}

TEST_CASE("the same scene renders to identical bytes") {
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  Scene scene = test::redCapsuleScene();
  scene.spheres.push_back({{0.5, 0.3, 0}, 0.07, {0.3f, 0.3f, 0.35f, 1.0f}});
  scene.capsules.push_back({{0, 0, 0}, {-0.4, 0.4, 0}, 0.05, {0.2f, 0.5f, 0.9f, 0.4f}});
  scene.polylines.push_back({{{-0.9, -0.5, 0}, {0, -0.6, 0}, {0.9, -0.4, 0}}, 2.0, {0, 0.5f, 0, 1}});
  const Overlay overlay = test::sampleOverlay();
  const Image first = renderer.render(scene, &overlay);
  const Image second = renderer.render(scene, &overlay);
  CHECK(first.rgba == second.rgba);
  // A second renderer (fresh ImGui state) draws the same first frame.
  Renderer other(*context);
  CHECK(other.render(scene, &overlay).rgba == first.rgba);
}

TEST_CASE("the overlay panel is drawn top-left on the first frame") {
  auto context = makeOffscreenContext(320, 240);
  const Scene scene = test::redCapsuleScene();
  const Overlay overlay = test::sampleOverlay();
  Renderer with_panel(*context);
  const Image with = with_panel.render(scene, &overlay);  // first frame of this renderer
  Renderer without_panel(*context);
  const Image without = without_panel.render(scene, nullptr);
  // Count differing pixels in the top-left 100x60 region; elsewhere far away, none differ.
  int changed = 0, changed_far = 0;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 100; ++x)
      changed += std::equal(with.pixel(x, y), with.pixel(x, y) + 4, without.pixel(x, y)) ? 0 : 1;
  for (int y = 200; y < 240; ++y)
    for (int x = 280; x < 320; ++x)
      changed_far += std::equal(with.pixel(x, y), with.pixel(x, y) + 4, without.pixel(x, y)) ? 0 : 1;
  CHECK(changed > 2000);
  CHECK(changed_far == 0);
  // The translucent panel keeps the frame opaque (alpha 255 everywhere).
  bool opaque = true;
  for (std::size_t i = 3; i < with.rgba.size(); i += 4) opaque = opaque && with.rgba[i] == 255;
  CHECK(opaque);
  // Options can switch the overlay off even when one is passed.
  Renderer hidden(*context, RenderOptions{4, false});
  CHECK(hidden.render(scene, &overlay).rgba == without.rgba);
}

TEST_CASE("MSAA off still renders the capsule") {
  auto context = makeOffscreenContext(160, 120);
  Renderer renderer(*context, RenderOptions{0, true});
  const Scene scene = test::redCapsuleScene();
  const Image image = renderer.render(scene, nullptr);
  const Eigen::Vector2d px = Renderer::project(scene.camera, 160, 120, {0.25, 0.15, 0});
  CHECK(reddish(image.pixel(int(px.x()), int(px.y()))));
}

TEST_CASE("perspective cameras project to the drawn pixels too") {
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  Scene scene = test::redCapsuleScene();
  scene.camera.ortho = false;
  scene.camera.eye = {0.6, 0.5, 1.5};
  scene.camera.target = {0.25, 0.15, 0};
  const Image image = renderer.render(scene, nullptr);
  for (double t : {0.2, 0.5, 0.8}) {
    const Eigen::Vector2d px =
        Renderer::project(scene.camera, 320, 240, t * Eigen::Vector3d(0.5, 0.3, 0));
    INFO("t=" << t << " px=" << px.transpose());
    CHECK(reddish(image.pixel(int(px.x()), int(px.y()))));
  }
  // The look-at target is the image centre.
  const Eigen::Vector2d centre = Renderer::project(scene.camera, 320, 240, scene.camera.target);
  CHECK(centre.x() == doctest::Approx(160.0));
  CHECK(centre.y() == doctest::Approx(120.0));
}

TEST_CASE("a small sphere's pixel centroid is where project() says, to half a pixel") {
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  for (bool ortho : {true, false}) {
    Scene scene;
    scene.camera.ortho = ortho;
    const Eigen::Vector3d centre(0.31, -0.27, 0.05);
    scene.spheres.push_back({centre, 0.06, {0.9f, 0.1f, 0.1f, 1.0f}});
    const Image image = renderer.render(scene, nullptr);
    // Coverage-weighted centroid of the red pixels (pixel centres at +0.5).
    double sx = 0, sy = 0, sw = 0;
    for (int y = 0; y < 240; ++y)
      for (int x = 0; x < 320; ++x) {
        const double w = (scene.background.g * 255.0 - image.pixel(x, y)[1]) / 255.0;
        if (w <= 0) continue;
        sx += w * (x + 0.5);
        sy += w * (y + 0.5);
        sw += w;
      }
    REQUIRE(sw > 20);
    const Eigen::Vector2d px = Renderer::project(scene.camera, 320, 240, centre);
    INFO("ortho=" << ortho << " projected " << px.transpose() << " centroid " << sx / sw << " "
                  << sy / sw);
    CHECK(std::abs(sx / sw - px.x()) < 0.5);
    CHECK(std::abs(sy / sw - px.y()) < 0.5);
  }
}

TEST_CASE("an ortho camera shows at least half_width and half_height, whichever binds at the aspect") {
  Camera cam;
  cam.target = {0.3, -0.1, 0};
  cam.eye = cam.target + Eigen::Vector3d(0, 0, 5);
  cam.half_width = 1.2;
  cam.half_height = 0.5;
  for (auto [w, h] : {std::pair{640, 480}, {1920, 1080}, {480, 480}, {1500, 400}}) {
    CAPTURE(w);
    CAPTURE(h);
    // The corners of the demanded rectangle are inside the frame, and one pair of sides touches it.
    const Eigen::Vector2d lo = Renderer::project(cam, w, h, cam.target + Eigen::Vector3d(-1.2, -0.5, 0));
    const Eigen::Vector2d hi = Renderer::project(cam, w, h, cam.target + Eigen::Vector3d(1.2, 0.5, 0));
    CHECK(lo.x() >= -1e-6);
    CHECK(hi.x() <= w + 1e-6);
    CHECK(hi.y() >= -1e-6);  // y down: the top corner has the smaller row
    CHECK(lo.y() <= h + 1e-6);
    const bool width_binds = std::abs(lo.x()) < 1e-6 && std::abs(hi.x() - w) < 1e-6;
    const bool height_binds = std::abs(hi.y()) < 1e-6 && std::abs(lo.y() - h) < 1e-6;
    CHECK((width_binds || height_binds));
    CHECK(width_binds == (double(w) / h < 1.2 / 0.5));
  }
}

TEST_CASE("the overlay panel grows with the frame in whole steps (a 1080p still reads like 480p)") {
  const Scene scene = test::redCapsuleScene();
  const Overlay overlay = test::sampleOverlay();
  // The panel's extent: rows and columns, counted from the top-left, that differ from no panel.
  auto panelWidth = [&](int w, int h) {
    auto context = makeOffscreenContext(w, h);
    Renderer with(*context), without(*context);
    const Image a = with.render(scene, &overlay), b = without.render(scene, nullptr);
    int right = 0;
    for (int y = 0; y < h / 2; ++y)
      for (int x = 0; x < w / 2; ++x)
        if (!std::equal(a.pixel(x, y), a.pixel(x, y) + 4, b.pixel(x, y))) right = std::max(right, x);
    return right;
  };
  const int small = panelWidth(640, 480), large = panelWidth(1920, 1080);
  MESSAGE("panel right edge: ", small, " px at 480p, ", large, " px at 1080p");
  CHECK(large > 1.8 * small);
  CHECK(large < 2.2 * small);
}
