// Tests for the primitives labs use beyond capsules and boxes: cylinders with spokes, planes
// with paths on them, friction cones, springs, and perspective framing of 3-D scenes. With
// DYNLAB_RENDER_DEMO_DIR set, also writes the demo scenes as PNGs there (to look at them).
#include <doctest/doctest.h>

#include <array>
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

namespace {

using Eigen::Vector3d;

// Pixel helpers: a shaded pixel of a saturated colour is dominated by that channel.
bool dominated(const std::uint8_t* p, int channel) {
  const int v = p[channel], o1 = p[(channel + 1) % 3], o2 = p[(channel + 2) % 3];
  return v > 110 && o1 < 0.6 * v && o2 < 0.6 * v;
}
bool reddish(const std::uint8_t* p) { return dominated(p, 0); }
bool greenish(const std::uint8_t* p) { return dominated(p, 1); }
bool bluish(const std::uint8_t* p) { return dominated(p, 2); }
bool isBackground(const std::uint8_t* p, const Color& c) {
  const float want[3] = {c.r, c.g, c.b};
  for (int i = 0; i < 3; ++i)
    if (std::abs(int(p[i]) - int(want[i] * 255.0f + 0.5f)) > 2) return false;
  return true;
}
bool samePixel(const Image& a, const Image& b, int x, int y) {
  return std::equal(a.pixel(x, y), a.pixel(x, y) + 4, b.pixel(x, y));
}

constexpr int kW = 320, kH = 240;
const Color kRed{0.9f, 0.1f, 0.1f, 1.0f}, kGreen{0.1f, 0.8f, 0.1f, 1.0f}, kBlue{0.1f, 0.2f, 0.9f, 1.0f};

// The pixel a world point lands on.
const std::uint8_t* at(const Image& image, const Camera& camera, const Vector3d& world) {
  const Eigen::Vector2d px = Renderer::project(camera, image.width, image.height, world);
  REQUIRE(px.x() >= 0);
  REQUIRE(px.y() >= 0);
  REQUIRE(px.x() < image.width);
  REQUIRE(px.y() < image.height);
  return image.pixel(int(px.x()), int(px.y()));
}

// A spoked disk facing an ortho camera: face blue, spokes red.
Scene diskScene(double spin) {
  Scene scene;
  scene.cylinders.push_back({{0.1, -0.05, 0}, axisSpin(Vector3d::UnitZ(), spin), 0.6, 0.03, kBlue, 4, kRed});
  return scene;
}

}  // namespace

TEST_CASE("a cylinder is drawn where project() says: a disk face-on, a rod side-on") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  Scene scene = diskScene(0.0);
  scene.cylinders[0].spokes = 0;
  const Image disk = renderer.render(scene, nullptr);
  const Vector3d c = scene.cylinders[0].center;
  for (double a = 0; a < 6.28; a += 0.5) {
    const Vector3d dir(std::cos(a), std::sin(a), 0);
    CAPTURE(a);
    CHECK(bluish(at(disk, scene.camera, c + 0.9 * 0.6 * dir)));
    CHECK(isBackground(at(disk, scene.camera, c + 1.08 * 0.6 * dir), scene.background));
  }
  // Side-on: a rod along world x, 0.4 long, radius 0.1, under a perspective camera.
  Scene rod;
  rod.camera.ortho = false;
  rod.camera.eye = {0.2, 0.3, 2.0};
  rod.cylinders.push_back({{0, 0, 0}, axisSpin(Vector3d::UnitX(), 0), 0.1, 0.4, kGreen});
  const Image side = renderer.render(rod, nullptr);
  for (double x : {-0.35, 0.0, 0.35}) CHECK(greenish(at(side, rod.camera, {x, 0, 0.09})));
  CHECK(isBackground(at(side, rod.camera, {0.47, 0, 0}), rod.background));
  CHECK(isBackground(at(side, rod.camera, {-0.47, 0, 0}), rod.background));
  CHECK(isBackground(at(side, rod.camera, {0, 0.14, 0}), rod.background));
}

TEST_CASE("a disk's spokes turn with its rotation; its rim does not change") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  const Scene s0 = diskScene(0.0), s1 = diskScene(0.3);
  const Image a = renderer.render(s0, nullptr), b = renderer.render(s1, nullptr);
  const Vector3d c = s0.cylinders[0].center;
  const double r = s0.cylinders[0].radius;
  // The first spoke lies along +x at spin 0 and along angle 0.3 after the turn.
  CHECK(reddish(at(a, s0.camera, c + 0.5 * r * Vector3d(1, 0, 0))));
  CHECK(bluish(at(b, s1.camera, c + 0.5 * r * Vector3d(1, 0, 0))));
  CHECK(reddish(at(b, s1.camera, c + 0.5 * r * Vector3d(std::cos(0.3), std::sin(0.3), 0))));
  // Pixels differ inside the wheel, and not in the ring outside the spokes' reach.
  int changed_inside = 0, changed_rim = 0, rim_pixels = 0;
  const Eigen::Vector2d centre = Renderer::project(s0.camera, kW, kH, c);
  const double r_px = Renderer::project(s0.camera, kW, kH, c + Vector3d(r, 0, 0)).x() - centre.x();
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const double rho = (Eigen::Vector2d(x + 0.5, y + 0.5) - centre).norm() / r_px;
      const bool differs = !samePixel(a, b, x, y);
      if (rho < 0.85) changed_inside += differs;
      if (rho > 0.96 && rho < 1.1) {
        ++rim_pixels;
        changed_rim += differs;
      }
    }
  CHECK(changed_inside > 500);
  CHECK(rim_pixels > 200);
  CHECK(changed_rim == 0);
}

TEST_CASE("a cone opens from its apex along its axis with its half-angle") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  Scene scene;
  const Vector3d apex(-0.5, 0.1, 0), axis(1, 0, 0);
  const double half_angle = std::atan(0.5), length = 0.8;
  scene.cones.push_back({apex, axis * 3.0, half_angle, length, kGreen});
  const Image image = renderer.render(scene, nullptr);
  // Inside the wedge: near the axis, and just inside the edge at 3/4 of the length.
  for (double t : {0.2, 0.5, 0.9}) CHECK(greenish(at(image, scene.camera, apex + t * length * axis)));
  CHECK(greenish(at(image, scene.camera, apex + Vector3d(0.6, 0.9 * 0.6 * 0.5, 0))));
  // Outside: past the edge, behind the apex, beyond the base.
  CHECK(isBackground(at(image, scene.camera, apex + Vector3d(0.6, 1.15 * 0.6 * 0.5, 0)), scene.background));
  CHECK(isBackground(at(image, scene.camera, apex - Vector3d(0.05, 0, 0)), scene.background));
  CHECK(isBackground(at(image, scene.camera, apex + Vector3d(length + 0.05, 0, 0)), scene.background));
}

TEST_CASE("a translucent cone over an arrow blends the two colours") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  Scene scene;
  scene.arrows.push_back({{-0.5, 0, 0}, {0.7, 0, 0}, 0.03, kBlue});
  const Image bare = renderer.render(scene, nullptr);
  scene.cones.push_back({{-0.5, 0, 0}, {1, 0, 0}, 0.5, 0.6, {0.9f, 0.1f, 0.1f, 0.5f}});
  const Image covered = renderer.render(scene, nullptr);
  const std::uint8_t* under = at(bare, scene.camera, {-0.2, 0, 0.0});
  const std::uint8_t* blend = at(covered, scene.camera, {-0.2, 0, 0.0});
  CHECK(bluish(under));
  // Half red over the blue shaft: both show, neither dominates as it did alone.
  CHECK(blend[0] > under[0] + 40);
  CHECK(blend[2] > 50);
  CHECK(blend[2] < under[2] - 30);
  // The cone over the background alone is a pale red, not the arrow's colour.
  const std::uint8_t* cone_only = at(covered, scene.camera, {-0.2, 0.1, 0.0});
  CHECK(cone_only[0] > cone_only[2] + 60);
}

TEST_CASE("a spring's coil stays within its radius between its end points") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  Scene scene;
  const Vector3d p0(-0.6, -0.1, 0), p1(0.5, -0.1, 0);
  scene.springs.push_back({p0, p1, 0.1, kRed, 6, 0.012});
  const Image image = renderer.render(scene, nullptr);
  // The straight leads lie on the axis.
  CHECK(reddish(at(image, scene.camera, p0 + Vector3d(0.03, 0, 0))));
  CHECK(reddish(at(image, scene.camera, p1 - Vector3d(0.03, 0, 0))));
  // Rows across the coil: red pixels only within radius + wire of the axis, and some near it.
  int inside = 0, outside = 0;
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      if (!reddish(image.pixel(x, y))) continue;
      const double world_y = -(y + 0.5 - kH / 2.0) / (kH / 2.0);  // ortho, half height 1
      (std::abs(world_y + 0.1) <= 0.1 + 0.012 + 0.01 ? inside : outside)++;
    }
  CHECK(inside > 300);
  CHECK(outside == 0);
  CHECK(isBackground(at(image, scene.camera, p1 + Vector3d(0.05, 0, 0)), scene.background));
}

TEST_CASE("a path lying on a table shows where project() says under a perspective camera") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  for (const Vector3d& from : {Vector3d(0.6, -1.2, 1.0), Vector3d(0.2, -1.0, 0.12)}) {
    CAPTURE(from.transpose());
    Scene scene;
    scene.planes.push_back({{0, 0, 0}, Eigen::Matrix3d::Identity(), {0.5, 0.35}, {0.75f, 0.75f, 0.75f, 1.0f},
                            0.03, 0.1, {0.2f, 0.2f, 0.9f, 1.0f}});
    Polyline path{{}, 3.0, kRed};
    for (int i = 0; i <= 60; ++i) {
      const double a = 2 * test::kPi * i / 60;
      path.points.push_back({0.2 * std::cos(a), 0.15 * std::sin(a), 0.0});  // exactly on the surface
    }
    scene.polylines.push_back(path);
    scene.camera.ortho = false;
    scene.camera.up = Vector3d::UnitZ();
    scene.camera.lookAtBox({-0.5, -0.35, -0.03}, {0.5, 0.35, 0.0}, from, double(kW) / kH);
    const Image image = renderer.render(scene, nullptr);
    // Every sample of the path is red: no z-fighting with the table or its grid, even grazing.
    for (const auto& p : path.points) CHECK(reddish(at(image, scene.camera, p)));
    // The table is lit grey between the grid lines, and the grid line at x = -0.3 shows along its length.
    // (Seen grazing, 0.1 m of table is a few pixels: only from above is there room between lines.)
    const std::uint8_t* top = at(image, scene.camera, {0.05, 0.05, 0});
    CHECK((from.z() < 0.5 || std::abs(top[0] - top[2]) < 4));
    CHECK((from.z() < 0.5 || top[0] > 100));
    int grid = 0;
    for (int i = 0; i < 20; ++i) {
      const std::uint8_t* p = at(image, scene.camera, {-0.3, 0.3 * (i / 20.0 - 0.5), 0});
      grid += p[2] > p[0] + 25;
    }
    CHECK(grid >= 10);
    // Just off the table's left edge: background.
    CHECK(isBackground(at(image, scene.camera, {-0.56, 0, 0}), scene.background));
  }
}

TEST_CASE("lookAtBox fits a box's corners in the frame, centred, tight on one side") {
  const Vector3d lo(-0.5, -0.3, -0.2), hi(0.7, 0.4, 0.6);
  for (bool ortho : {false, true})
    for (auto [w, h] : {std::pair{640, 480}, {1280, 720}, {400, 600}})
      for (const Vector3d& from : {Vector3d(0.6, -1.2, 1.0), Vector3d(0, 0, 1), Vector3d(-1, 0.2, 0.1)}) {
        CAPTURE(ortho);
        CAPTURE(w);
        CAPTURE(from.transpose());
        Camera cam;
        cam.ortho = ortho;
        cam.up = Vector3d::UnitZ();
        cam.lookAtBox(lo, hi, from, double(w) / h, 1.1);
        CHECK((cam.eye - cam.target).normalized().isApprox(from.normalized(), 1e-9));
        double x_lo = 1e9, x_hi = -1e9, y_lo = 1e9, y_hi = -1e9;
        for (int i = 0; i < 8; ++i) {
          const Vector3d c((i & 1 ? hi : lo).x(), (i & 2 ? hi : lo).y(), (i & 4 ? hi : lo).z());
          const Eigen::Vector2d px = Renderer::project(cam, w, h, c);
          x_lo = std::min(x_lo, px.x()), x_hi = std::max(x_hi, px.x());
          y_lo = std::min(y_lo, px.y()), y_hi = std::max(y_hi, px.y());
          // In front of the camera, well past the near plane.
          CHECK((cam.eye - c).dot((cam.eye - cam.target).normalized()) > 0.05 * (cam.eye - cam.target).norm());
        }
        CHECK(x_lo >= 0);
        CHECK(x_hi <= w);
        CHECK(y_lo >= 0);
        CHECK(y_hi <= h);
        // The box fills 1/margin of the width or of the height, and its picture is centred.
        const double fill = std::max((x_hi - x_lo) / w, (y_hi - y_lo) / h);
        CHECK(fill == doctest::Approx(1 / 1.1).epsilon(0.02));
        CHECK(std::abs(0.5 * (x_lo + x_hi) - 0.5 * w) < 0.02 * w);
        CHECK(std::abs(0.5 * (y_lo + y_hi) - 0.5 * h) < 0.02 * h);
      }
}

TEST_CASE("axisSpin: z along the axis, x turned by spin from up (or from x for a vertical axis)") {
  const Vector3d axle = Vector3d(1, 2, 0).normalized();
  const Eigen::Matrix3d r0 = axisSpin(axle * 2.0, 0.0), r1 = axisSpin(axle, 0.4);
  CHECK((r0.transpose() * r0).isIdentity(1e-12));
  CHECK(r0.determinant() == doctest::Approx(1.0));
  CHECK(r0.col(2).isApprox(axle));
  CHECK(r0.col(0).isApprox(Vector3d::UnitZ()));  // an upright wheel's first spoke points up
  CHECK(r1.col(0).dot(r0.col(0)) == doctest::Approx(std::cos(0.4)));
  CHECK(r1.col(0).isApprox(Eigen::AngleAxisd(0.4, axle) * r0.col(0)));
  CHECK(axisSpin(Vector3d::UnitZ(), 0.0).isApprox(Eigen::Matrix3d::Identity()));
}

TEST_CASE("inkStrokes splits the pen's samples where it was lifted") {
  std::vector<Vector3d> p;
  for (int i = 0; i < 10; ++i) p.push_back({double(i), 0, 0});
  const std::vector<bool> down = {true, true, true, false, true, false, false, true, true, true};
  const auto strokes = inkStrokes(p, down, 3.0, kRed);
  REQUIRE(strokes.size() == 2);  // the lone sample 4 draws nothing
  CHECK(strokes[0].points.size() == 3);
  CHECK(strokes[1].points.front().x() == 7.0);
  CHECK(strokes[1].width_px == 3.0);
  CHECK(inkStrokes(p, std::vector<bool>(10, false), 2.0, kRed).empty());
}

TEST_CASE("the demo scenes render to the same bytes twice, and in a fresh renderer") {
  auto context = makeOffscreenContext(kW, kH);
  const double aspect = double(kW) / kH;
  const Scene scenes[] = {test::penOnTableScene({}, aspect), test::wheelScene({}, aspect), test::graspScene(),
                          test::springScene()};
  Renderer renderer(*context);
  for (const Scene& scene : scenes) {
    const Image first = renderer.render(scene, nullptr);
    CHECK(renderer.render(scene, nullptr).rgba == first.rgba);
    Renderer fresh(*context);
    CHECK(fresh.render(scene, nullptr).rgba == first.rgba);
  }
}

TEST_CASE("the pen's ink is drawn on the table, with a gap where the pen was lifted") {
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  const test::PenDemo d;
  const Scene scene = test::penOnTableScene(d, 640.0 / 480.0);
  const Image image = renderer.render(scene, nullptr);
  // The ink is near black; the desired circle's blue may blend into its edge.
  auto inkAt = [&](double angle) {
    const double r = d.circle_radius * (0.97 + 0.02 * std::sin(5 * angle));
    const std::uint8_t* p = at(image, scene.camera, d.circle_centre + r * Vector3d(std::cos(angle), std::sin(angle), 0));
    return std::array<int, 3>{p[0], p[1], p[2]};
  };
  auto isInk = [](const std::array<int, 3>& p) { return p[0] < 60 && p[1] < 60 && p[2] < 110; };
  for (double a : {0.3, 1.0, 1.5, 2.5, 3.5}) {
    const auto p = inkAt(a);
    INFO("angle " << a << ": " << p[0] << " " << p[1] << " " << p[2]);
    CHECK(isInk(p));
  }
  CHECK_FALSE(isInk(inkAt(0.5 * (d.lift_from + d.lift_to))));
  CHECK_FALSE(isInk(inkAt(d.pen_angle + 0.6)));  // not drawn yet
}

TEST_CASE("perspective scenes of 0.1 m to 5 m keep their depth order and lose nothing to near/far") {
  auto context = makeOffscreenContext(kW, kH);
  Renderer renderer(*context);
  for (double s : {0.1, 1.0, 5.0}) {
    CAPTURE(s);
    Scene scene;
    scene.camera.ortho = false;
    scene.camera.up = Vector3d::UnitZ();
    const Vector3d from(0.5, -1.0, 0.7);
    scene.camera.lookAtBox(Vector3d::Constant(-s), Vector3d::Constant(s), from, double(kW) / kH);
    // A red ball at the centre with a blue one just in front of it (towards the camera).
    scene.spheres.push_back({Vector3d::Zero(), 0.2 * s, kRed});
    scene.spheres.push_back({0.3 * s * from.normalized(), 0.08 * s, kBlue});
    // Small green balls at the box's corners: the nearest and farthest test the clip planes.
    std::vector<Vector3d> corners;
    for (int i = 0; i < 8; ++i) corners.push_back({i & 1 ? s : -s, i & 2 ? s : -s, i & 4 ? s : -s});
    for (const auto& c : corners) scene.spheres.push_back({c, 0.03 * s, kGreen});
    const Image image = renderer.render(scene, nullptr);
    CHECK(bluish(at(image, scene.camera, Vector3d::Zero())));
    CHECK(reddish(at(image, scene.camera, 0.15 * s * Vector3d(from.y(), -from.x(), 0).normalized())));
    for (const auto& c : corners) {
      CAPTURE(c.transpose());
      CHECK(greenish(at(image, scene.camera, c)));
    }
  }
}
