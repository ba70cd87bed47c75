// What the data labs' frames show (labs/generic/data_lab.cpp's scene and overlay, labs/model_scene's
// picture), measured from rendered images:
//  * framing: each data lab's mechanism (its links and joints alone, drawn through the frame's own
//    camera) spans at least 75 % of the width or the height of the part of the frame the panel leaves
//    free, over the frames of a run (the camera holds still while the arm moves), and never lies under
//    the panel;
//  * a spatial arm stands on something: a floor slab and a pedestal reaching up to its base joint;
//  * the push: an arrow ending on the tool while the push acts, none before it; drawn, the frame has
//    many more pixels of the arrow's red during the push than before;
//  * the live plot is what is graded: an impedance exercise plots |x − x_target| (the dev columns).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "labs/generic/data_lab.h"
#include "labs/model_scene.h"
#include "labs/settings.h"
#include "tests/render/test_scene.h"

using namespace dyn;

namespace {

struct Loaded {
  json config;
  generic::DataSettings settings;
  std::unique_ptr<generic::DataLab> lab;
  Trace trace;
};

Loaded load(const std::string& name) {
  Loaded l;
  const std::string folder = std::string(DYNLAB_SOURCE_DIR) + "/labs/" + name;
  l.config = loadJsonFile(folder + "/" + name + ".json");
  l.settings = generic::parseDataSettings(JsonView(l.config, folder + "/" + name + ".json"), name, folder);
  l.lab = std::make_unique<generic::DataLab>(l.settings);
  l.trace.columns = l.lab->columns();
  auto sim = l.lab->simulate(Engine::Hand);
  std::vector<double> row;
  while (sim->step(row)) l.trace.append(row);
  return l;
}

std::size_t rowAt(const Trace& tr, double t) {
  std::size_t r = 0;
  while (r + 1 < tr.rows() && tr.at(r, "t") < t - 1e-9) ++r;
  return r;
}

// Pixels of the force arrow's red (shaded): red well above green and blue.
int redPixels(const Image& image) {
  int n = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      n += p[0] > 120 && p[1] < 0.35 * p[0] && p[2] < 0.35 * p[0] ? 1 : 0;
    }
  return n;
}

}  // namespace

TEST_CASE("each data lab's mechanism fills at least 75 % of the free part of its frames, clear of the panel") {
  for (const char* name : {"fivebar", "puma_motion", "puma_impedance"}) {
    INFO(std::string(name));
    const Loaded l = load(name);
    REQUIRE(l.trace.rows() > 100);
    const ModelPicture picture(*l.settings.plant);
    const int n = int(l.settings.plant->joints.size());
    auto context = makeOffscreenContext(960, 540);
    Renderer renderer(*context);
    PixelRect free, panel, ink;
    double x0 = 1e9, y0 = 1e9, x1 = -1, y1 = -1;
    for (int k = 0; k <= 8; ++k) {
      const std::size_t row = (l.trace.rows() - 1) * std::size_t(k) / 8;
      Scene scene;
      Overlay overlay;
      l.lab->scene(l.trace, row, nullptr, scene);
      l.lab->overlay(l.trace, row, overlay);
      renderer.render(scene, &overlay);
      free = renderer.sceneRect(), panel = renderer.panelRect();
      // The mechanism alone (links, joints, mounts), through the frame's camera.
      Scene alone;
      picture.scene(traceQ(l.trace, row, n), nullptr, scene.framing.bounds, alone);
      alone.framing.fit = false;
      alone.camera = renderer.camera();
      ink = test::inkBox(renderer.render(alone, nullptr), alone.background);
      REQUIRE_FALSE(ink.empty());
      CHECK_FALSE(ink.intersects(panel));
      x0 = std::min(x0, ink.x), y0 = std::min(y0, ink.y), x1 = std::max(x1, ink.right()), y1 = std::max(y1, ink.bottom());
    }
    const double wide = (x1 - x0) / free.w, tall = (y1 - y0) / free.h;
    const std::string lab = name;
    MESSAGE(lab << ": the mechanism spans " << 100 * wide << " % of the free width, " << 100 * tall << " % of its height");
    CHECK(std::max(wide, tall) >= 0.75);
  }
}

TEST_CASE("a spatial arm stands on a floor and a pedestal up to its base; a planar one keeps its mounts") {
  const Loaded puma = load("puma_impedance");
  Scene s;
  puma.lab->scene(puma.trace, 0, nullptr, s);
  REQUIRE(s.planes.size() == 1);
  const Plane& floor = s.planes[0];
  CHECK(floor.rotation.col(2).isApprox(Eigen::Vector3d::UnitZ()));
  CHECK(floor.grid > 0);
  // A column from the floor up to joint 1's anchor (the world origin).
  bool pedestal = false;
  for (const Cylinder& c : s.cylinders) {
    const Eigen::Vector3d top = c.center + c.half_length * c.rotation.col(2), bottom = c.center - c.half_length * c.rotation.col(2);
    pedestal = pedestal || (top.norm() < 1e-9 && std::abs(bottom.z() - floor.center.z()) < 1e-9);
  }
  CHECK(pedestal);
  const Loaded fivebar = load("fivebar");
  Scene f;
  fivebar.lab->scene(fivebar.trace, 0, nullptr, f);
  CHECK(f.planes.empty());
  CHECK(f.cylinders.empty());
}

TEST_CASE("the push's arrow ends on the tool while the push acts, and not before; the plot is the graded distance") {
  const Loaded l = load("puma_impedance");
  const double start = l.config["environment"]["force"]["start"].get<double>();
  const std::size_t before = rowAt(l.trace, 0.5 * start), during = rowAt(l.trace, start + 0.6);
  REQUIRE(l.trace.at(before, "push_x") == 0.0);
  REQUIRE(l.trace.at(during, "push_x") > 0.0);
  Scene a, b;
  l.lab->scene(l.trace, before, nullptr, a);
  l.lab->scene(l.trace, during, nullptr, b);
  CHECK(a.arrows.empty());
  REQUIRE(b.arrows.size() == 1);
  const Arrow& arrow = b.arrows[0];
  const Eigen::Vector3d tool(l.trace.at(during, "tool_x"), l.trace.at(during, "tool_y"), l.trace.at(during, "tool_z"));
  const Eigen::Vector3d push(l.trace.at(during, "push_x"), l.trace.at(during, "push_y"), l.trace.at(during, "push_z"));
  CHECK(arrow.vector.normalized().isApprox(push.normalized(), 1e-12));
  CHECK((arrow.origin + arrow.vector - tool).norm() < 0.03);  // its head at the tool's ball
  // Drawn: the arrow's red is in the frame during the push only.
  auto context = makeOffscreenContext(960, 540);
  Renderer renderer(*context);
  Overlay none;
  const int red_before = redPixels(renderer.render(a, nullptr)), red_during = redPixels(renderer.render(b, nullptr));
  MESSAGE("red pixels before the push " << red_before << ", during it " << red_during);
  CHECK(red_during > red_before + 500);
  // The live plot: |x − x_target| in mm, the rubric's dev columns, not the tracking error |e|.
  Overlay o;
  l.lab->overlay(l.trace, during, o);
  REQUIRE(o.plots.size() == 1);
  CHECK(o.plots[0].name.find("x_target") != std::string::npos);
  const double dev = 1e3 * std::sqrt(std::pow(l.trace.at(during, "dev_x"), 2) + std::pow(l.trace.at(during, "dev_y"), 2) +
                                     std::pow(l.trace.at(during, "dev_z"), 2));
  CHECK(o.plots[0].values.back() == doctest::Approx(dev).epsilon(1e-5));
}
