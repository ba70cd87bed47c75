// A model file's meshes drawn as the triangles MuJoCo decoded (model_file.h Geom::Shape::Mesh), against
// the files' own numbers: tests/models/mesh_arm (written as MuJoCo Menagerie writes robots: meshes in a
// subfolder, materials, a floor, visual and collision copies in separate groups) has its box and its
// tetrahedron drawn with every triangle, each vertex where the file puts it (MuJoCo moved the mesh to its
// inertial frame and the geom's pose with it), in its material's colour; the collision copies are not
// drawn a second time, and that is noted.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>

#include "physics/model_file/model_file.h"

using namespace dyn;
using model_file::Geom;
using Eigen::Vector3d;

namespace {

std::string meshArm() { return std::string(DYNLAB_SOURCE_DIR) + "/tests/models/mesh_arm/mesh_arm.xml"; }

const Geom* named(const model_file::LoadedModel& m, const std::string& name) {
  for (const Geom& g : m.drawing.geoms)
    if (g.name == name) return &g;
  return nullptr;
}

// The mesh's vertices in its link's frame (on the joint's anchor, world-aligned at q0).
std::vector<Vector3d> placed(const Geom& g) {
  std::vector<Vector3d> out;
  for (const Eigen::Vector3f& v : g.mesh->vertices) out.push_back(g.pos + g.rot * v.cast<double>());
  return out;
}

// True when every point of `got` is one of `want` and every point of `want` one of `got` (to float
// precision; MuJoCo may repeat a vertex for each face it is on).
bool sameSet(const std::vector<Vector3d>& got, const std::vector<Vector3d>& want) {
  auto within = [](const std::vector<Vector3d>& a, const std::vector<Vector3d>& b) {
    return std::all_of(a.begin(), a.end(), [&](const Vector3d& p) {
      return std::any_of(b.begin(), b.end(), [&](const Vector3d& q) { return (p - q).norm() < 1e-6; });
    });
  };
  return !got.empty() && within(got, want) && within(want, got);
}

}  // namespace

TEST_CASE("a mesh in a subfolder is drawn as its triangles, where the file puts its vertices, in its material's colour") {
  const model_file::LoadedModel m = model_file::load(meshArm());
  const Geom* block = named(m, "block_visual");
  REQUIRE(block);
  REQUIRE(block->shape == Geom::Shape::Mesh);
  REQUIRE(block->mesh);
  CHECK(block->mesh->triangles.size() == 12);
  CHECK(block->link == 0);
  // block.obj's corners (±0.2, ±0.03, ±0.03) at the geom's pos (0.2, 0, 0), in link1's frame.
  std::vector<Vector3d> corners;
  for (int k = 0; k < 8; ++k) corners.push_back({0.2 + (k & 1 ? 0.2 : -0.2), k & 2 ? 0.03 : -0.03, k & 4 ? 0.03 : -0.03});
  CHECK(sameSet(placed(*block), corners));
  CHECK(block->file_color);
  CHECK(block->rgba[0] == doctest::Approx(0.85f));
  CHECK(block->rgba[2] == doctest::Approx(0.1f));
  // Every triangle names vertices the mesh has; the triangles enclose the box (their signed volumes
  // add up to 0.4 × 0.06 × 0.06: none lost, none turned).
  double volume = 0;
  for (const auto& t : block->mesh->triangles) {
    for (auto i : t) REQUIRE(i < block->mesh->vertices.size());
    const Eigen::Vector3d a = block->mesh->vertices[t[0]].cast<double>(), b = block->mesh->vertices[t[1]].cast<double>(),
                          c = block->mesh->vertices[t[2]].cast<double>();
    volume += a.dot(b.cross(c)) / 6;
  }
  CHECK(volume == doctest::Approx(0.4 * 0.06 * 0.06).epsilon(1e-5));

  // The tetrahedron on link2, on its joint's anchor (0.4, 0, 0.5): the file's four vertices.
  const Geom* tip = named(m, "tip_visual");
  REQUIRE(tip);
  REQUIRE(tip->shape == Geom::Shape::Mesh);
  CHECK(tip->link == 1);
  CHECK(tip->mesh->triangles.size() == 4);
  CHECK(sameSet(placed(*tip), {{-0.05, -0.05, 0.02}, {0.08, -0.05, 0.02}, {-0.05, 0.08, 0.02}, {0, 0, -0.25}}));
  CHECK(tip->rgba[2] == doctest::Approx(0.85f));
}

TEST_CASE("a body drawn twice, visual-only and colliding in another group, is drawn once; floors and pedestals stay") {
  const model_file::LoadedModel m = model_file::load(meshArm());
  CHECK(named(m, "block_collision") == nullptr);  // group 3: hidden, as MuJoCo's viewer hides it
  CHECK(named(m, "tip_collision") == nullptr);    // group 0, beside a visual-only copy in group 1
  REQUIRE(named(m, "floor"));
  CHECK(named(m, "floor")->shape == Geom::Shape::Plane);
  REQUIRE(named(m, "pedestal"));
  CHECK(named(m, "pedestal")->shape == Geom::Shape::Cylinder);
  CHECK(m.drawing.geoms.size() == 4);
  const auto& notes = m.drawing.notes;
  CHECK(std::any_of(notes.begin(), notes.end(), [](const std::string& n) {
    return n.find("1 colliding geom not drawn") != std::string::npos && n.find("visual-only") != std::string::npos;
  }));
  // No mesh falls back to a bounding capsule.
  CHECK(std::none_of(notes.begin(), notes.end(), [](const std::string& n) { return n.find("bounding capsule") != std::string::npos; }));
}
