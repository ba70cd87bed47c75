// What a model file draws (model_file.h Drawing), against the file's own numbers: the four-bar's
// capsules end where its fromto says, on the tree bodies their MuJoCo bodies move with, and its pin
// is where the connect's anchor is; a mesh is drawn as its triangles, its vertices where the file
// lists them (model_file_mesh_test.cpp: meshes from files); an ellipsoid as a capsule that holds its
// semi-axes; a plane is a floor; hidden and transparent geoms are left out and each substitution is
// noted; a URDF without geoms is drawn as rods.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <unistd.h>

#include "physics/model_file/model_file.h"

using namespace dyn;
using model_file::Geom;
using Eigen::Vector3d;
namespace fs = std::filesystem;

namespace {

std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

bool has(const std::vector<std::string>& notes, const std::string& a, const std::string& b) {
  return std::any_of(notes.begin(), notes.end(), [&](const std::string& n) { return n.find(a) != std::string::npos && n.find(b) != std::string::npos; });
}

// Distance from p to a capsule's segment (both in the same frame).
double toSegment(const Geom& g, const Vector3d& p) {
  const Vector3d a = g.pos - g.size[1] * g.rot.col(2), b = g.pos + g.size[1] * g.rot.col(2);
  const Vector3d ab = b - a;
  const double t = ab.squaredNorm() > 0 ? std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

const Geom& named(const model_file::LoadedModel& m, const std::string& name) {
  for (const Geom& g : m.drawing.geoms)
    if (g.name == name) return g;
  FAIL("no geom " << name);
  throw 0;
}

}  // namespace

TEST_CASE("the four-bar's capsules are drawn where its file puts them, on the bodies that carry them") {
  const model_file::LoadedModel m = model_file::load(model("fourbar.xml"));
  REQUIRE(m.drawing.geoms.size() == 3);
  CHECK(m.drawing.bones.empty());
  // Each capsule's ends in its tree body's frame (on the joint's anchor, world-aligned at q0), from the
  // file's fromto less the anchor: crank at A = 0, coupler at B = (0, 0, 0.2), rocker at D = (0.5, 0, 0).
  const Vector3d ends[3][2] = {{{0, 0, 0}, {0, 0, 0.2}}, {{0, 0, 0}, {0.4, 0, 0.1}}, {{0, 0, 0}, {-0.1, 0, 0.3}}};
  for (int i = 0; i < 3; ++i) {
    const Geom& g = m.drawing.geoms[std::size_t(i)];
    INFO("geom ", i, " on ", g.body);
    CHECK(g.shape == Geom::Shape::Capsule);
    CHECK(g.link == i);
    CHECK(g.size[0] == doctest::Approx(0.015));
    CHECK_FALSE(g.file_color);
    const Vector3d p0 = g.pos - g.size[1] * g.rot.col(2), p1 = g.pos + g.size[1] * g.rot.col(2);
    const double d = std::min((p0 - ends[i][0]).norm() + (p1 - ends[i][1]).norm(), (p1 - ends[i][0]).norm() + (p0 - ends[i][1]).norm());
    CHECK(d < 1e-9);
  }
  // The pin: the connect's anchor (0.4, 0, 0.1) in the coupler's frame, C less D in the rocker's.
  REQUIRE(m.closures.size() == 1);
  CHECK(m.closures[0].link1 == 1);
  CHECK(m.closures[0].link2 == 2);
  CHECK((m.closures[0].point1 - Vector3d(0.4, 0, 0.1)).norm() < 1e-12);
  CHECK((m.closures[0].point2 - Vector3d(-0.1, 0, 0.3)).norm() < 1e-12);
}

TEST_CASE("meshes as triangles, ellipsoids as bounding capsules, planes as floors, hidden geoms left out, each noted") {
  const fs::path file = fs::temp_directory_path() / ("dynlab_drawing_" + std::to_string(::getpid()) + ".xml");
  // A wedge mesh (vertices as the file lists them, in its body's frame), off-centre and long along y.
  std::ofstream(file) << R"(<mujoco>
  <default><geom contype="0" conaffinity="0"/></default>
  <asset>
    <mesh name="wedge" vertex="0 0 0  0.1 0 0  0 0.5 0  0 0 0.05  0.1 0.5 0.05  0.02 0.3 0.01"/>
    <material name="red" rgba="0.8 0.1 0.1 1"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1" pos="0 0 -1"/>
    <geom name="huge" type="box" size="1e12 1 1"/>
    <body name="arm" pos="0.2 0.1 0">
      <joint name="j" type="hinge" axis="0 1 0"/>
      <geom name="wedge" type="mesh" mesh="wedge" mass="1"/>
      <geom name="egg" type="ellipsoid" size="0.05 0.2 0.1" pos="0.3 0 0" euler="0 0 30" mass="0.5"/>
      <geom name="painted" type="box" size="0.01 0.02 0.03" material="red" mass="0.1"/>
      <geom name="collision" type="sphere" size="0.3" group="3" mass="0.1"/>
      <geom name="ghost" type="sphere" size="0.3" rgba="1 1 1 0" mass="0.1"/>
    </body>
  </worldbody>
</mujoco>)";
  const model_file::LoadedModel m = model_file::load(file.string());
  fs::remove(file);
  const auto& notes = m.drawing.notes;
  INFO(notes.size());
  CHECK(m.drawing.geoms.size() == 4);  // floor, wedge, egg, painted
  // The mesh: its triangles (MuJoCo's hull of the listed vertices), every vertex the file lists where it
  // lists it, in the body's frame (= the hinge's frame: the anchor is the body's origin).
  const Geom& wedge = named(m, "wedge");
  CHECK(wedge.shape == Geom::Shape::Mesh);
  CHECK(wedge.link == 0);
  REQUIRE(wedge.mesh);
  CHECK(wedge.mesh->triangles.size() >= 4);
  const double v[6][3] = {{0, 0, 0}, {0.1, 0, 0}, {0, 0.5, 0}, {0, 0, 0.05}, {0.1, 0.5, 0.05}, {0.02, 0.3, 0.01}};
  for (const auto& p : v)
    CHECK(std::any_of(wedge.mesh->vertices.begin(), wedge.mesh->vertices.end(), [&](const Eigen::Vector3f& q) {
      return (wedge.pos + wedge.rot * q.cast<double>() - Vector3d(p[0], p[1], p[2])).norm() < 1e-6;
    }));
  CHECK_FALSE(has(notes, "wedge", "bounding capsule"));
  // The ellipsoid: its six semi-axis ends inside, its capsule along its longest (y, turned 30° about z).
  const Geom& egg = named(m, "egg");
  CHECK(egg.shape == Geom::Shape::Capsule);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(30 * EIGEN_PI / 180, Vector3d::UnitZ()).toRotationMatrix();
  const double axes[3] = {0.05, 0.2, 0.1};
  for (int k = 0; k < 3; ++k)
    for (double s : {-1.0, 1.0}) CHECK(toSegment(egg, Vector3d(0.3, 0, 0) + s * axes[k] * R.col(k)) <= egg.size[0] + 1e-9);
  CHECK(std::abs(egg.rot.col(2).dot(R.col(1))) == doctest::Approx(1.0));
  CHECK(has(notes, "egg", "ellipsoid"));
  // The floor stays with the world; the material's colour is the box's.
  const Geom& floor = named(m, "floor");
  CHECK(floor.shape == Geom::Shape::Plane);
  CHECK(floor.link == -1);
  CHECK((floor.pos - Vector3d(0, 0, -1)).norm() < 1e-12);
  CHECK(has(notes, "floor", "plane"));
  const Geom& painted = named(m, "painted");
  CHECK(painted.file_color);
  CHECK(painted.rgba[0] == doctest::Approx(0.8f));
  CHECK(has(notes, "1 geom", "groups 3"));
  CHECK(has(notes, "1 transparent", "not drawn"));
  CHECK(has(notes, "huge", "beyond ±1e9 m, not drawn"));
}

TEST_CASE("a URDF arm without geoms is drawn as rods from each joint to the next and to its centre of mass") {
  const model_file::LoadedModel m = model_file::load(model("planar_arm.urdf"));
  CHECK(m.drawing.geoms.empty());
  for (int link = 0; link < 3; ++link) {
    INFO("link ", link);
    CHECK(std::any_of(m.drawing.bones.begin(), m.drawing.bones.end(), [&](const model_file::Bone& b) { return b.link == link; }));
  }
  // link1: from the shoulder to the elbow, 0.3 m along x.
  CHECK(std::any_of(m.drawing.bones.begin(), m.drawing.bones.end(), [](const model_file::Bone& b) {
    return b.link == 0 && b.from.norm() < 1e-12 && (b.to - Vector3d(0.3, 0, 0)).norm() < 1e-12;
  }));
  CHECK(has(m.drawing.notes, "link1", "no geom"));
}
