// Files laid out as users lay robots out (physics/model_file/packages.cpp): a URDF in robot/urdf/
// whose meshes are package://robot/meshes/…, package://assets/… beside the file, a package found
// through --package-path (LoadOptions::package_paths) or ROS_PACKAGE_PATH, ../meshes inside a ROS
// package (package.xml above), file:// paths. Each loads and reads the bytes meant (the drawn
// capsule's size follows the mesh written); a missing package or file is one line naming the
// name and where dynlab looked.
#include <doctest/doctest.h>
#include <stdlib.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>

#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"
#include "tests/physics/model_file/mesh_files.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

using dyn::test_model_file::meshArmUrdf;
using dyn::test_model_file::tetrahedronStl;

fs::path folder() {
  static const fs::path dir = test_model_file::scratchFolder("model_packages");
  return dir;
}

fs::path write(const std::string& name, const std::string& text) { return test_model_file::writeFile(folder(), name, text); }

// The size of the capsule drawn for the model's one mesh: it scales with the mesh MuJoCo read.
double drawnSize(const fs::path& file, const model_file::LoadOptions& options = {}) {
  const model_file::LoadedModel m = model_file::load(file.string(), options);
  REQUIRE(m.drawing.geoms.size() == 1);
  return m.drawing.geoms[0].size.norm();
}

std::string errorOf(const fs::path& file) { return test_model_file::errorOf(file); }

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("package://NAME/… is found in the folders above the file, beside them, through --package-path and ROS_PACKAGE_PATH") {
  // robot/urdf/arm.urdf naming package://robot/meshes/body.stl: the folder above is the package.
  write("robot/meshes/body.stl", tetrahedronStl(0.1f));
  const double ref = drawnSize(write("robot/urdf/arm.urdf", meshArmUrdf("package://robot/meshes/body.stl")));
  CHECK(ref > 0.01);
  // package://assets/body.stl beside the file: assets/ is the package (was "not in the model's folder").
  write("flat/assets/body.stl", tetrahedronStl(0.2f));
  CHECK(drawnSize(write("flat/arm.urdf", meshArmUrdf("package://assets/body.stl"))) == doctest::Approx(2 * ref).epsilon(0.02));
  // A package elsewhere: not found until named by --package-path or ROS_PACKAGE_PATH; each then read.
  write("elsewhere/parts/meshes/body.stl", tetrahedronStl(0.3f));
  const fs::path far = write("ws/far.urdf", meshArmUrdf("package://parts/meshes/body.stl"));
  const std::string missing = errorOf(far);
  CHECK(has(missing, "file 'package://parts/meshes/body.stl' not found (no package folder 'parts' in the folders above "));
  CHECK(has(missing, "--package-path DIR"));
  model_file::LoadOptions options;
  options.package_paths = {(folder() / "elsewhere").string()};
  CHECK(drawnSize(far, options) == doctest::Approx(3 * ref).epsilon(0.02));
  options.package_paths = {(folder() / "elsewhere/parts").string()};  // the package folder itself
  CHECK(drawnSize(far, options) == doctest::Approx(3 * ref).epsilon(0.02));
  REQUIRE(::setenv("ROS_PACKAGE_PATH", ("/nonexistent:" + (folder() / "elsewhere").string()).c_str(), 1) == 0);
  CHECK(drawnSize(far) == doctest::Approx(3 * ref).epsilon(0.02));
  ::unsetenv("ROS_PACKAGE_PATH");
  // The package is found but lacks the file: where dynlab looked.
  CHECK(has(errorOf(write("robot/urdf/typo.urdf", meshArmUrdf("package://robot/meshes/bodyy.stl"))),
            "file 'package://robot/meshes/bodyy.stl' not found (looked in package 'robot' at "));
}

TEST_CASE("meshes beside a URDF's folder load inside a ROS package; file:// is a path; outside stays refused") {
  write("pkg/meshes/body.stl", tetrahedronStl(0.1f));
  const fs::path up = write("pkg/urdf/up.urdf", meshArmUrdf("../meshes/body.stl"));
  CHECK(has(errorOf(up), "outside the model's folder"));  // no package.xml: not a package
  write("pkg/package.xml", "<package><name>pkg</name></package>");
  CHECK(drawnSize(up) > 0.01);
  // file:// with an absolute path inside the package, and a relative one.
  CHECK(drawnSize(write("pkg/urdf/abs.urdf", meshArmUrdf("file://" + (folder() / "pkg/meshes/body.stl").string()))) > 0.01);
  CHECK(drawnSize(write("pkg/urdf/rel.urdf", meshArmUrdf("file://../meshes/body.stl"))) > 0.01);
  // A package:// name does not open the rest of the disk: no system folder is a package.
  CHECK(has(errorOf(write("pkg/urdf/dev.urdf", meshArmUrdf("package://dev/zero"))), "no package folder 'dev'"));
  CHECK(has(errorOf(write("pkg/urdf/etc.urdf", meshArmUrdf("package://etc/passwd"))), "no package folder 'etc'"));
  fs::remove_all(folder());
}

namespace {

// A URDF arm whose link has a visual mesh and a collision mesh of the same file name in two folders
// (meshes/visual/body.stl, meshes/collision/body.stl: how Bullet's and ROS's Panda ship), with `extra`
// inside <robot>.
std::string visualAndCollisionUrdf(const std::string& extra) {
  std::string u = meshArmUrdf("meshes/collision/body.stl");
  u.replace(u.find("<collision>"), 0, "<visual><geometry><mesh filename=\"meshes/visual/body.stl\"/></geometry></visual>");
  return u.replace(u.find("<link"), 0, extra);
}

}  // namespace

TEST_CASE("a URDF's visual and collision meshes of one file name: the collision's is read while MuJoCo discards visuals") {
  write("twin/meshes/collision/body.stl", tetrahedronStl(0.1f));
  write("twin/meshes/visual/body.stl", tetrahedronStl(0.3f));
  const double collision = drawnSize(write("twin/arm.urdf", visualAndCollisionUrdf("")));
  CHECK(collision == doctest::Approx(drawnSize(write("twin/plain.urdf", meshArmUrdf("meshes/collision/body.stl")))));
  // Kept visuals: MuJoCo would read one file for both names, so the file is refused in one line.
  const std::string kept = errorOf(write("twin/kept.urdf", visualAndCollisionUrdf("<mujoco><compiler discardvisual=\"false\"/></mujoco>")));
  CHECK(has(kept, "another file named 'body.stl' is named too (MuJoCo finds files by name alone: rename one)"));
  CHECK(kept.find('\n') == std::string::npos);
  fs::remove_all(folder() / "twin");
}

TEST_CASE("a URDF's <mimic> is said to be not held, with the way to hold it") {
  std::string u = meshArmUrdf("meshes/collision/body.stl");
  write("mimic/meshes/collision/body.stl", tetrahedronStl(0.1f));
  u.insert(u.find("</joint>"), "<mimic joint=\"j0\"/>");
  const model_file::LoadedModel m = model_file::load(write("mimic/arm.urdf", u).string());
  const auto note = std::find_if(m.notes.begin(), m.notes.end(), [](const std::string& n) { return has(n, "URDF <mimic> element(s) not held"); });
  REQUIRE(note != m.notes.end());
  CHECK(has(*note, "1 URDF <mimic>"));
  CHECK(has(*note, "<equality><joint joint1 joint2 polycoef"));
  fs::remove_all(folder() / "mimic");
}

TEST_CASE("a URDF is read as XML: a <mimic> or </visual> in a comment or CDATA is none; XML's quoting and spacing; broken XML is one line") {
  write("xml/meshes/collision/body.stl", tetrahedronStl(0.1f));
  write("xml/meshes/visual/body.stl", tetrahedronStl(0.3f));
  auto mimicNote = [](const model_file::LoadedModel& m) {
    return std::any_of(m.notes.begin(), m.notes.end(), [](const std::string& n) { return has(n, "<mimic>"); });
  };
  // A <mimic> commented out, and one as CDATA text: no note.
  std::string u = meshArmUrdf("meshes/collision/body.stl");
  u.insert(u.find("</joint>"), "<!-- <mimic joint=\"j0\"/> --><![CDATA[<mimic joint=\"j0\"/>]]>");
  CHECK_FALSE(mimicNote(model_file::load(write("xml/commented.urdf", u).string())));
  // A "</visual>" in a comment inside the visual: its mesh stays a discarded visual, the collision's is read.
  std::string v = visualAndCollisionUrdf("");
  v.insert(v.find("<visual>") + 8, "<!-- </visual> -->");
  const double collision = drawnSize(write("xml/plain.urdf", meshArmUrdf("meshes/collision/body.stl")));
  CHECK(drawnSize(write("xml/comment_in_visual.urdf", v)) == doctest::Approx(collision));
  // discardvisual = 'false' with spaces around '=' and single quotes keeps the visuals (refused, as above);
  // one in a comment keeps nothing.
  const std::string kept = errorOf(write("xml/kept.urdf", visualAndCollisionUrdf("<mujoco><compiler\n  discardvisual = 'false' /></mujoco>")));
  CHECK(has(kept, "another file named 'body.stl' is named too"));
  CHECK(drawnSize(write("xml/kept_in_comment.urdf", visualAndCollisionUrdf("<!-- <mujoco><compiler discardvisual=\"false\"/></mujoco> -->"))) ==
        doctest::Approx(collision));
  // Not well-formed (an element left open), with a <mimic> and twin meshes: MuJoCo's parser says so, in
  // one line naming the file (not the two meshes' names, which a broken file cannot tell apart).
  std::string broken = visualAndCollisionUrdf("");
  broken.insert(broken.find("</joint>"), "<mimic joint=\"j0\"/>");
  broken.erase(broken.find("</link>"), 7);
  const std::string error = errorOf(write("xml/broken.urdf", broken));
  CHECK(has(error, "broken.urdf"));
  CHECK(has(error, "XML parse error"));
  CHECK_FALSE(has(error, "another file named"));
  CHECK(error.find('\n') == std::string::npos);
  fs::remove_all(folder() / "xml");
}
