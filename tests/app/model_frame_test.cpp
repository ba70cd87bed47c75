// A model file drawn (labs/model_scene.h) as every lab is: the four-bar's frame at its file pose and
// mid-swing has ink (the mechanism, not the background) where its joint anchors and its loop's pin
// project, none in the gap between the ground pivots, nothing of it under the overlay panel, and it
// fills the part of the frame the panel leaves free (not a speck). The spatial arm is drawn in
// perspective, framed the same way.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>

#include "labs/generic/model_run.h"
#include "labs/model_scene.h"
#include "physics/constrained_mechanism.h"
#include "physics/integrate.h"
#include "render/framing.h"
#include "render/renderer.h"

using namespace dyn;
using Eigen::Vector3d;

namespace {

std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

// A pixel the background colour shows through (within a few levels of shading).
bool background(const Image& image, const Scene& scene, int x, int y) {
  const std::uint8_t* p = image.pixel(x, y);
  const float want[3] = {scene.background.r, scene.background.g, scene.background.b};
  for (int i = 0; i < 3; ++i)
    if (std::abs(int(p[i]) - int(want[i] * 255.0f + 0.5f)) > 6) return false;
  return true;
}

// Ink on a 3×3 patch around the pixel a world point projects to, inside the free part of the frame.
void checkInkAt(const Image& image, const Scene& scene, const Renderer& r, const Vector3d& world, const char* what) {
  const Eigen::Vector2d px = Renderer::project(r.camera(), image.width, image.height, world);
  INFO(what, " at pixel (", px.x(), ", ", px.y(), ")");
  const PixelRect free = r.sceneRect();
  REQUIRE(px.x() >= free.x);
  REQUIRE(px.x() < free.right());
  REQUIRE(px.y() >= free.y);
  REQUIRE(px.y() < free.bottom());
  CHECK_FALSE(r.panelRect().intersects({px.x() - 1, px.y() - 1, 2, 2}));
  int inked = 0;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) inked += !background(image, scene, int(px.x()) + dx, int(px.y()) + dy);
  CHECK(inked == 9);
}

}  // namespace

TEST_CASE("the four-bar from its file: ink where its joints and pin project, framed beside the panel") {
  const model_file::LoadedModel m = model_file::load(model("fourbar.xml"));
  const ModelPicture picture(m);
  CHECK(picture.planar());
  // A state mid-swing: 0.3 s of the passive run from the file's pose.
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  VecN q = m.q0, v = VecN::Zero(3);
  StepOptions o;
  for (int k = 0; k < 300; ++k) REQUIRE(step(mech, o, VecN::Zero(3), q, v));
  REQUIRE((q - m.q0).norm() > 0.3);
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  for (const VecN& state : {m.q0, q}) {
    Scene scene;
    picture.scene(state, nullptr, {}, scene);
    CHECK(scene.framing.fit);
    CHECK(scene.camera.ortho);
    Overlay panel;
    panel.title = "fourbar.xml";
    panel.lines = {{"t", "0.000 s"}, {"energy E", "1.6 J"}, {"closure |phi|", "1e-13"}};
    const Image image = renderer.render(scene, &panel);
    // Seen side-on: world x to the right, z up (the hinges turn about y).
    const Eigen::Vector2d a = Renderer::project(renderer.camera(), 640, 480, {0, 0, 0});
    const Eigen::Vector2d d = Renderer::project(renderer.camera(), 640, 480, {0.5, 0, 0});
    CHECK(d.x() > a.x() + 100);
    CHECK(std::abs(d.y() - a.y()) < 1);
    const std::vector<Vector3d> anchors = picture.anchors(state);
    REQUIRE(anchors.size() == 3);
    checkInkAt(image, scene, renderer, anchors[0], "crank's pivot A");
    checkInkAt(image, scene, renderer, anchors[1], "coupler's joint B");
    checkInkAt(image, scene, renderer, anchors[2], "rocker's pivot D");
    // The loop's pin C, where the coupler's anchor of the connect is.
    ConstrainedMechanism<Spatial> at(m.mechanism);
    const Vector3d c = at.pointPosition(m.closures[0].link1, m.closures[0].point1, state);
    checkInkAt(image, scene, renderer, c, "pin C");
    // Halfway between the ground pivots, below the pin: nothing is drawn there.
    const Eigen::Vector2d gap = Renderer::project(renderer.camera(), 640, 480, {0.25, 0, -0.02});
    CHECK(background(image, scene, int(gap.x()), int(gap.y())));
    // Not a speck: the mechanism's box fills the free part of the frame in one direction.
    const PixelRect box = projectedBox(renderer.camera(), 640, 480, scene.framing.bounds), free = renderer.sceneRect();
    CHECK_FALSE(box.intersects(renderer.panelRect()));
    CHECK(std::max(box.w / free.w, box.h / free.h) > 0.8);
  }
}

TEST_CASE("a spatial arm is drawn in perspective, its joints inked, and a URDF without geoms as rods") {
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  for (const char* file : {"arm3d.xml", "planar_arm.urdf"}) {
    INFO(file);
    const model_file::LoadedModel m = model_file::load(model(file));
    const ModelPicture picture(m);
    Scene scene;
    picture.scene(m.q0, nullptr, {}, scene);
    CHECK(scene.camera.ortho == picture.planar());
    const Image image = renderer.render(scene, nullptr);
    const std::vector<Vector3d> anchors = picture.anchors(m.q0);
    for (std::size_t i = 0; i < anchors.size(); ++i) checkInkAt(image, scene, renderer, anchors[i], m.joints[i].name.c_str());
    const PixelRect box = projectedBox(renderer.camera(), 640, 480, scene.framing.bounds), free = renderer.sceneRect();
    CHECK(std::max(box.w / free.w, box.h / free.h) > 0.8);
  }
}

TEST_CASE("a falling floating base is framed on the robot, not on the box of its whole fall") {
  // The Cassie-style leg (tests' leg_loops.xml) falls 1.8 m in 0.6 s: a picture framed on that whole
  // path shows the leg at a third of the frame's height; one that follows the base, nearly all of it.
  const model_file::LoadedModel m = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/leg_loops.xml");
  const ModelPicture picture(m);
  REQUIRE(picture.follows());
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  const app::ModelRun run = app::runHand(m, mech, m.timestep, 0.6, VecN::Zero(mech.nv()));
  REQUIRE(run.ok);
  const int n = int(m.q0.size());
  const VecN first = traceQ(run.trace, 0, n), last = traceQ(run.trace, run.trace.rows() - 1, n);
  REQUIRE(picture.base(first).z() - picture.base(last).z() > 1.5);
  const Eigen::AlignedBox3d bounds = runBounds(picture, n, run.trace, nullptr);
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  for (const VecN& q : {first, last}) {
    Scene scene;
    picture.scene(q, nullptr, bounds, scene);
    renderer.render(scene, nullptr);
    // The leg as drawn at this row fills the free part of the frame in one direction.
    const PixelRect box = projectedBox(renderer.camera(), 640, 480, picture.bounds(q)), free = renderer.sceneRect();
    MESSAGE("the leg's box over the free frame: " << box.w / free.w << " wide, " << box.h / free.h << " high");
    CHECK(std::max(box.w / free.w, box.h / free.h) > 0.6);
  }
}
