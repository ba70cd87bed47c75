// A model's size counted before MuJoCo compiles it (physics/model_file/sizes.cpp): bodies, joints,
// geoms and equalities past model_file.h's limits, counted through includes as often as they are
// written, are one line naming the count and the limit, quickly; a file that includes itself and a
// <composite> are refused by name; a model just within the limits still loads, and the cross-check
// reads the model compiled at load (the file gone by then).
#include <doctest/doctest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

fs::path folder() {
  static const fs::path dir = test_model_file::scratchFolder("model_sizes");
  return dir;
}

fs::path write(const std::string& name, const std::string& text) { return test_model_file::writeFile(folder(), name, text); }

// One hinged body holding the geoms given, then `rest` inside <worldbody>, `top` beside it.
std::string model(const std::string& rest, const std::string& top = "") {
  return "<mujoco><option><flag contact=\"disable\"/></option><worldbody><body name=\"arm\"><joint name=\"j\"/>"
         "<geom size=\"0.1\"/></body>" + rest + "</worldbody>" + top + "</mujoco>";
}

std::string repeat(const std::string& s, int n) {
  std::string out;
  for (int i = 0; i < n; ++i) out += s;
  return out;
}

// The one-line error (fixtures.h), within 5 s.
std::string errorOf(const fs::path& file) {
  double seconds = 0;
  const std::string what = test_model_file::errorOf(file, &seconds);
  CHECK(seconds < 5.0);
  return what;
}

}  // namespace

TEST_CASE("bodies, joints, geoms and equalities past the limits are counted and named before MuJoCo compiles") {
  const fs::path bodies = write("bodies.xml", model(repeat("<body><geom size=\"0.1\"/></body>", 47000)));
  CHECK(errorOf(bodies) == bodies.string() + ": 47001 bodies, more than the 1000 a model file may have");
  const fs::path geoms = write("geoms.xml", model("<body>" + repeat("<geom size=\"0.1\"/>", 6000) + "</body>"));
  CHECK(errorOf(geoms).find(": 6001 geoms, more than the 5000 a model file may have") != std::string::npos);
  const fs::path joints = write("joints.xml", model("<body>" + repeat("<joint/>", 1200) + "<geom size=\"0.1\"/></body>"));
  CHECK(errorOf(joints).find(": 1201 joints, more than the 1000") != std::string::npos);
  const fs::path eq = write("eq.xml", model("", "<equality>" + repeat("<connect body1=\"arm\" anchor=\"0 0 0\"/>", 201) + "</equality>"));
  CHECK(errorOf(eq).find(": 201 equalities, more than the 200") != std::string::npos);
  // A URDF's links.
  const fs::path urdf = write("links.urdf", "<robot name=\"r\">" + repeat("<link name=\"l\"/>", 1001) + "</robot>");
  CHECK(errorOf(urdf).find(": 1001 links, more than the 1000") != std::string::npos);
}

TEST_CASE("includes count as often as they are written; one that includes itself is refused by name") {
  write("two.xml", "<mujoco><body><geom size=\"0.1\"/></body><body><geom size=\"0.1\"/></body></mujoco>");
  const fs::path twice = write("twice.xml", model(repeat("<include file=\"two.xml\"/>", 600)));
  CHECK(errorOf(twice).find(": 1201 bodies, more than the 1000") != std::string::npos);
  const fs::path self = write("self.xml", "<mujoco><worldbody><include file=\"self.xml\"/></worldbody></mujoco>");
  CHECK(errorOf(self).find("includes nested deeper than 8 (at 'self.xml'") != std::string::npos);
  const fs::path composite = write("composite.xml", model("<composite type=\"grid\" count=\"1000 1000 1\" spacing=\"0.01\"/>"));
  CHECK(errorOf(composite).find("<composite> makes bodies the file does not write out") != std::string::npos);
}

TEST_CASE("a model within the limits loads, and MuJoCo's cross-check reads the model compiled at load") {
  // 999 bodies fused into the world (no joints) beside the arm: within every limit.
  const fs::path file = write("within.xml", model(repeat("<body><geom size=\"0.01\" contype=\"0\" conaffinity=\"0\"/></body>", 998)));
  const model_file::LoadedModel m = model_file::load(file.string());
  CHECK(m.joints.size() == 1);
  fs::remove(file);  // nothing reads the file again
  model_file::MujocoReference mj(m);
  CHECK(mj.nv() == 1);
  model_file::MujocoSimulation sim(m, 1e-3);
  sim.reset(m.q0, VecN::Zero(1));
  CHECK(sim.step());
  fs::remove_all(folder());
}
