// A model file's meshes in its frames (labs/model_scene.h, render/mesh_cache.cpp): tests/models/mesh_arm's
// box is drawn where its vertices project, in its material's red, its tetrahedron in blue, its floor
// under it; the frame is fitted to the points the shapes reach (every mesh vertex inside the part of the
// frame the panel leaves free, and the robot filling it), a second frame of the same scene is the same
// pixels, and the Bullet ghost at the same state leaves the robot's colours as they are.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>

#include "labs/model_scene.h"
#include "render/framing.h"
#include "render/renderer.h"

using namespace dyn;
using Eigen::Vector3d;

namespace {

std::string meshArm() { return std::string(DYNLAB_SOURCE_DIR) + "/tests/models/mesh_arm/mesh_arm.xml"; }

const model_file::Geom& named(const model_file::LoadedModel& m, const std::string& name) {
  for (const auto& g : m.drawing.geoms)
    if (g.name == name) return g;
  FAIL("no geom " << name);
  throw 0;
}

// The geom's vertices in the world at q0 (its link's frame is world-aligned there, on the link's anchor).
std::vector<Vector3d> worldVertices(const ModelPicture& picture, const model_file::LoadedModel& m, const std::string& name) {
  const model_file::Geom& g = named(m, name);
  const Vector3d anchor = picture.anchors(m.q0)[std::size_t(g.link)];
  std::vector<Vector3d> out;
  for (const Eigen::Vector3f& v : g.mesh->vertices) out.push_back(anchor + g.pos + g.rot * v.cast<double>());
  return out;
}

// The pixel a world point projects to, inside the frame.
const std::uint8_t* pixelAt(const Image& image, const Renderer& r, const Vector3d& world) {
  const Eigen::Vector2d px = Renderer::project(r.camera(), image.width, image.height, world);
  REQUIRE(px.x() >= 0);
  REQUIRE(px.y() >= 0);
  REQUIRE(px.x() < image.width);
  REQUIRE(px.y() < image.height);
  return image.pixel(int(px.x()), int(px.y()));
}

Vector3d mean(const std::vector<Vector3d>& points) {
  Vector3d s = Vector3d::Zero();
  for (const Vector3d& p : points) s += p;
  return s / double(points.size());
}

}  // namespace

TEST_CASE("a model's meshes are drawn in their materials' colours, on its floor, and frame the picture") {
  const model_file::LoadedModel m = model_file::load(meshArm());
  const ModelPicture picture(m);
  CHECK_FALSE(picture.planar());
  CHECK(picture.fitsPoints());
  std::vector<Vector3d> points;
  picture.shapePoints(m.q0, points);
  Scene scene;
  picture.scene(m.q0, nullptr, picture.bounds(m.q0), scene, points);
  REQUIRE(scene.meshes.size() == 2);
  CHECK(scene.planes.size() == 1);  // the file's floor
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  Overlay panel;
  panel.title = "mesh_arm.xml";
  panel.lines = {{"t", "0.000 s"}, {"energy E", "1.0 J"}};
  const Image image = renderer.render(scene, &panel);

  // The box's middle in red (its material 0.85 0.12 0.1, lit), the tetrahedron's in blue.
  const std::vector<Vector3d> block = worldVertices(picture, m, "block_visual"), tip = worldVertices(picture, m, "tip_visual");
  const std::uint8_t* red = pixelAt(image, renderer, mean(block));
  INFO("box's middle: ", int(red[0]), " ", int(red[1]), " ", int(red[2]));
  CHECK(red[0] > red[1] + 60);
  CHECK(red[0] > red[2] + 60);
  const std::uint8_t* blue = pixelAt(image, renderer, mean(tip));
  INFO("tetrahedron's middle: ", int(blue[0]), " ", int(blue[1]), " ", int(blue[2]));
  CHECK(blue[2] > blue[0] + 60);
  CHECK(blue[2] > blue[1] + 40);

  // Framed by what the shapes reach: every mesh vertex and the pedestal's foot inside the free part of
  // the frame, clear of the panel, and together filling it (not a speck in a box's corner).
  std::vector<Vector3d> shown = block;
  shown.insert(shown.end(), tip.begin(), tip.end());
  shown.push_back({0, 0, 0});  // the pedestal's foot on the floor
  const PixelRect reach = projectedPoints(renderer.camera(), 640, 480, shown), free = renderer.sceneRect();
  INFO("reach ", reach.x, " ", reach.y, " ", reach.w, " ", reach.h, "; free ", free.x, " ", free.y, " ", free.w, " ", free.h);
  CHECK(reach.x >= free.x);
  CHECK(reach.y >= free.y);
  CHECK(reach.right() <= free.right());
  CHECK(reach.bottom() <= free.bottom());
  CHECK_FALSE(reach.intersects(renderer.panelRect()));
  CHECK(std::max(reach.w / free.w, reach.h / free.h) > 0.85);

  // Drawn again (the meshes already uploaded): the same pixels.
  const Image again = renderer.render(scene, &panel);
  CHECK(again.rgba == image.rgba);

  // With the other engine's ghost at the same state: its meshes sit behind the robot's, so the box
  // keeps its own red (not the ghost's purple over it).
  Scene with_ghost;
  picture.scene(m.q0, &m.q0, picture.bounds(m.q0), with_ghost, points);
  CHECK(with_ghost.meshes.size() == 4);
  const Image ghosted = renderer.render(with_ghost, &panel);
  const std::uint8_t* still_red = pixelAt(ghosted, renderer, mean(block));
  for (int c = 0; c < 3; ++c) CHECK(still_red[c] == red[c]);
}
