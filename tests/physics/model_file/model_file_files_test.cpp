// What a model file names (physics/model_file/files.cpp): a mesh in a meshdir is read (its mass and
// centre follow the tetrahedron written, so MuJoCo had its bytes), and every hostile name (a
// FIFO, a link to /dev/zero, a file outside the folder, an absolute or escaped path, a huge file, two
// files of one name, a missing include) is one line naming the file, within a second, before MuJoCo
// opens anything.
#include <doctest/doctest.h>
#include <sys/stat.h>

#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"
#include "tests/physics/model_file/mesh_files.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

using dyn::test_model_file::tetrahedronStl;

// A fresh folder for this process's files (model files go in its "model" folder).
fs::path folder() {
  static const fs::path dir = [] {
    const fs::path d = test_model_file::scratchFolder("model_files");
    fs::create_directories(d / "model");
    return d;
  }();
  return dir;
}

fs::path write(const std::string& name, const std::string& text) { return test_model_file::writeFile(folder(), name, text); }

// A one-joint model naming assets (a mesh geom when mesh is given) and an extra top-level section.
std::string mjcf(const std::string& assets, const std::string& mesh = "", const std::string& extra = "") {
  return "<mujoco><compiler meshdir=\"meshes\"/><asset>" + assets + "</asset><worldbody><body name=\"b\"><joint name=\"j\"/>" +
         (mesh.empty() ? "<geom size=\"0.1\" contype=\"0\" conaffinity=\"0\"/>"
                       : "<geom type=\"mesh\" mesh=\"" + mesh + "\" density=\"1000\" contype=\"0\" conaffinity=\"0\"/>") +
         "</body></worldbody>" + extra + "</mujoco>";
}

// The one-line error (fixtures.h), within a second.
std::string errorOf(const fs::path& file, double* seconds = nullptr) {
  double s = 0;
  const std::string what = test_model_file::errorOf(file, &s);
  CHECK(s < 1.0);
  if (seconds) *seconds = s;
  return what;
}

}  // namespace

TEST_CASE("a mesh in the file's meshdir is read through the checked copy: its mass and centre follow its bytes") {
  // Two tetrahedra, edges 0.3 and 0.15 m: MuJoCo's mass from the mesh scales as the volume (8:1) and the
  // centre of mass sits at s/4 along each axis, so what it read is the bytes written.
  double mass[2] = {0, 0};
  const float sizes[2] = {0.3f, 0.15f};
  for (int k = 0; k < 2; ++k) {
    const std::string stl = "tet" + std::to_string(k) + ".stl";
    write("model/meshes/" + stl, tetrahedronStl(sizes[k]));
    const fs::path file = write("model/mesh" + std::to_string(k) + ".xml", mjcf("<mesh name=\"tet\" file=\"" + stl + "\"/>", "tet"));
    const model_file::LoadedModel m = model_file::load(file.string());
    Eigen::Vector3d com;
    Spatial::massAndCom(m.mechanism.tree.bodies[0].inertia, mass[k], com);
    CHECK((com - Eigen::Vector3d::Constant(sizes[k] / 4.0)).norm() < 1e-6);
  }
  CHECK(mass[1] > 0);
  CHECK(mass[0] / mass[1] == doctest::Approx(8.0).epsilon(1e-6));
}

TEST_CASE("what a model file names: hostile files get one line naming the file, within a second") {
  // A FIFO as a mesh: MuJoCo would block opening it for ever.
  const fs::path fifo = folder() / "model/meshes/pipe.stl";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  CHECK(errorOf(write("model/fifo.xml", mjcf("<mesh name=\"m\" file=\"pipe.stl\"/>", "m"))).find("file 'pipe.stl': not a regular file") !=
        std::string::npos);
  // A link in the folder to /dev/zero, /dev/zero by its path, and escaped: all outside the folder.
  fs::create_symlink("/dev/zero", folder() / "model/meshes/zero.stl");
  CHECK(errorOf(write("model/zero.xml", mjcf("<mesh name=\"m\" file=\"zero.stl\"/>", "m"))).find("resolves to /dev/zero, outside the model's folder") !=
        std::string::npos);
  CHECK(errorOf(write("model/abs.xml", mjcf("<mesh name=\"m\" file=\"/dev/zero\"/>", "m"))).find("outside the model's folder") != std::string::npos);
  CHECK(errorOf(write("model/escaped.xml", mjcf("<mesh name=\"m\" file=\"&#47;dev&#x2F;zero\"/>", "m"))).find("file '/dev/zero'") !=
        std::string::npos);
  CHECK(errorOf(write("model/entity.xml", mjcf("<mesh name=\"m\" file=\"&zero;\"/>", "m"))).find("holds an entity dynlab does not expand") !=
        std::string::npos);
  // An include from outside the folder.
  write("outside.xml", "<mujoco/>");
  CHECK(errorOf(write("model/up.xml", "<mujoco><include file=\"../outside.xml\"/></mujoco>")).find("outside the model's folder") != std::string::npos);
  // 100 MB (sparse): refused by its size before it is read; an included file as a model file is.
  const fs::path big = write("model/meshes/big.stl", "solid");
  fs::resize_file(big, 100u << 20);
  CHECK(errorOf(write("model/big.xml", mjcf("<mesh name=\"m\" file=\"big.stl\"/>", "m"))).find("104857600 bytes, more than the 16777216") !=
        std::string::npos);
  fs::remove(big);
  // An empty mesh: MuJoCo's file table takes no empty file (its error waited for Enter on stdin).
  write("model/meshes/empty.stl", "");
  CHECK(errorOf(write("model/empty.xml", mjcf("<mesh name=\"m\" file=\"empty.stl\"/>", "m"))).find("file 'empty.stl': empty (expected a mesh") !=
        std::string::npos);
  write("model/latin1_part.xml", "<mujoco model=\"caf\xE9\"/>");
  CHECK(errorOf(write("model/latin1_main.xml", "<mujoco><include file=\"latin1_part.xml\"/></mujoco>")).find("not valid UTF-8") != std::string::npos);
  // Two files of one name: MuJoCo would read the first for both.
  write("model/meshes/a/tet.stl", tetrahedronStl(0.1f));
  write("model/meshes/b/tet.stl", tetrahedronStl(0.2f));
  CHECK(errorOf(write("model/twins.xml", mjcf("<mesh name=\"m1\" file=\"a/tet.stl\"/><mesh name=\"m2\" file=\"b/tet.stl\"/>", "m1")))
            .find("another file named 'tet.stl'") != std::string::npos);
  // Named but missing: MuJoCo's own error, with the name it did not find (never the disk's elsewhere).
  CHECK(errorOf(write("model/missing.xml", "<mujoco><include file=\"nothere.xml\"/></mujoco>")).find("file 'nothere.xml' not found (looked in ") !=
        std::string::npos);
  // A file naming more files than allowed.
  std::string many;
  for (int i = 0; i <= model_file::kMaxAssetFiles; ++i) many += "<mesh name=\"m" + std::to_string(i) + "\" file=\"m" + std::to_string(i) + ".stl\"/>";
  CHECK(errorOf(write("model/many.xml", mjcf(many))).find("names more than 256 files") != std::string::npos);
  fs::remove_all(folder());
}
