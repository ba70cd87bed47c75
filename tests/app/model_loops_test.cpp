// Loop closures beside a URDF (labs/generic/model_loops.h): fourbar.urdf + fourbar.loops.json is fourbar.xml
// (M, h, φ, the constraint rows, the solve and a 1 s passive run, to 1e-12), a weld keeps the planar
// rows, and hostile loops files get one line naming the JSON file, the JSON path and what was expected.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <unistd.h>

#include "labs/generic/model_loops.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

using test_model_file::maxAbs;
using test_model_file::model;

fs::path scratch() {
  const fs::path dir = fs::path(DYNLAB_TEST_TMP) / ("model_loops_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = (scratch() / name).string();
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

// The error loading URDF with LOOPS gives: one line that starts with the loops file's name.
std::string errorOf(const std::string& urdf, const std::string& loops) {
  std::string what;
  try {
    app::loadWithLoops(urdf, loops);
  } catch (const model_file::ModelFileError& e) {
    what = e.what();
  }
  INFO(what);
  CHECK(what.find('\n') == std::string::npos);
  CHECK(what.rfind(loops + ": ", 0) == 0);
  return what;
}

}  // namespace

TEST_CASE("fourbar.urdf with fourbar.loops.json beside it equals fourbar.xml (M, h, rows, solve, a 1 s run; 1e-12)") {
  const model_file::LoadedModel xml = model_file::load(model("fourbar.xml"));
  // Found beside the URDF without being named.
  CHECK(app::loopsBeside(model("fourbar.urdf")) == model("fourbar.loops.json"));
  // fourbar.xml (its loop an equality) does not pick up fourbar.urdf's; an MJCF without a URDF of its
  // stem beside it picks up its own (dynlab's elements: unicycle.xml's wheel).
  CHECK(app::loopsBeside(model("fourbar.xml")).empty());
  CHECK(app::loopsBeside(model("unicycle.xml")) == model("unicycle.loops.json"));
  CHECK(app::loopsBeside(model("fivebar.xml")).empty());
  CHECK(app::loadWithLoops(model("fourbar.xml"), "").notes == xml.notes);
  const model_file::LoadedModel urdf = app::loadWithLoops(model("fourbar.urdf"), "");
  REQUIRE(urdf.closures.size() == 1);
  CHECK(urdf.closures[0].name == "pin_C");
  CHECK(urdf.closures[0].kind == "connect");
  CHECK(urdf.closures[0].kept == std::vector<std::string>{"x", "z"});
  CHECK(urdf.closures[0].dropped == std::vector<std::string>{"y"});
  CHECK(urdf.dof == 1);
  CHECK(urdf.q0 == xml.q0);
  // The URDF alone is an open 3-joint tree.
  CHECK(model_file::load(model("fourbar.urdf")).closures.empty());
  ConstrainedMechanism<Spatial> a(xml.mechanism), b(urdf.mechanism);
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    CAPTURE(trial);
    VecN q(3), v(3), tau(3);
    for (int i = 0; i < 3; ++i) q[i] = 2.0 * u(rng), v[i] = 3.0 * u(rng), tau[i] = u(rng);
    CHECK(maxAbs(a.massMatrix(q) - b.massMatrix(q)) < 1e-12);
    CHECK(maxAbs(a.inverseDynamics(q, v, VecN::Zero(3)) - b.inverseDynamics(q, v, VecN::Zero(3))) < 1e-12);
    test_model_file::checkSameConstraints(a, q, b, q, 2);
    const auto sa = a.solve(q, v, tau), sb = b.solve(q, v, tau);
    CHECK(maxAbs(sa.qdd - sb.qdd) < 1e-12 * std::max(1.0, maxAbs(sa.qdd)));
    CHECK(maxAbs(sa.eta - sb.eta) < 1e-12 * std::max(1.0, maxAbs(sa.eta)));
  }
  // 1 s passive from the closed pose at rest, RK4 + projection at 1 ms: the same path and pin force.
  StepOptions o;
  o.dt = 1e-3;
  VecN qa = xml.q0, va = VecN::Zero(3), qb = qa, vb = va;
  double dq = 0, dv = 0, deta = 0, swing = 0;
  for (int k = 0; k < 1000; ++k) {
    REQUIRE(step(a, o, VecN::Zero(3), qa, va));
    REQUIRE(step(b, o, VecN::Zero(3), qb, vb));
    dq = std::max(dq, maxAbs(qa - qb));
    dv = std::max(dv, maxAbs(va - vb));
    deta = std::max(deta, maxAbs(a.solve(qa, va, VecN::Zero(3)).eta - b.solve(qb, vb, VecN::Zero(3)).eta));
    swing = std::max(swing, maxAbs(qa - xml.q0));
  }
  MESSAGE("fourbar.urdf + loops vs fourbar.xml over 1 s: |dq| " << dq << ", |dv| " << dv << ", |d eta| " << deta << " N");
  CHECK(swing > 0.5);
  CHECK(dq < 1e-12);
  CHECK(dv < 1e-12);
  CHECK(deta < 1e-12);
}

TEST_CASE("a weld given beside the URDF keeps its planar rows and locks the four-bar") {
  const std::string loops = writeFile("weld.loops.json", R"({"loops": [{"name": "w", "kind": "weld", "body1": "coupler",
      "point1": [0.4, 0, 0.1], "body2": "rocker"}]})");
  const model_file::LoadedModel m = app::loadWithLoops(model("fourbar.urdf"), loops);
  REQUIRE(m.closures.size() == 1);
  CHECK(m.closures[0].kept == std::vector<std::string>{"wy", "x", "z"});
  CHECK(m.closures[0].dropped == std::vector<std::string>{"wx", "wz", "y"});
  CHECK(m.dof == 0);
  // point2 left out: the rocker's point is where the coupler's sits at the reference pose (C).
  CHECK((m.closures[0].point2 - Eigen::Vector3d(-0.1, 0, 0.3)).norm() < 1e-15);
}

TEST_CASE("hostile loops files: one line naming the file, the JSON path and what was expected") {
  const std::string urdf = model("fourbar.urdf");
  const std::string good = R"("kind": "connect", "body1": "coupler", "point1": [0.4, 0, 0.1], "body2": "rocker")";
  auto loops = [&](const std::string& name, const std::string& text) { return errorOf(urdf, writeFile(name, text)); };
  CHECK(errorOf(urdf, (scratch() / "none.json").string()).find("no such file") != std::string::npos);
  CHECK(loops("text.json", "loops: pin C").find("not JSON") != std::string::npos);
  CHECK(loops("array.json", "[1, 2]").find("expected an object {\"loops\": [...]}") != std::string::npos);
  CHECK(loops("typo.json", R"({"loops": [{)" + good + R"(}], "lops": 1})").find("lops: unknown key") != std::string::npos);
  CHECK(loops("empty.json", R"({"loops": []})").find("loops: expected an array of 1 to 64 closures") != std::string::npos);
  CHECK(loops("missing.json", R"({"loops": [{"kind": "connect", "body1": "coupler", "point1": [0, 0, 0]}]})")
            .find("loops[0].body2: missing") != std::string::npos);
  CHECK(loops("kind.json", R"({"loops": [{"kind": "ball", "body1": "coupler", "point1": [0.4, 0, 0.1], "body2": "rocker"}]})")
            .find("loops[0].kind: expected \"connect\" (3 translation rows) or \"weld\" (6 rows), got \"ball\"") != std::string::npos);
  CHECK(loops("point.json", R"({"loops": [{"kind": "connect", "body1": "coupler", "point1": [0.4, 0], "body2": "rocker"}]})")
            .find("loops[0].point1: expected [x, y, z] in metres, got [0.4,0]") != std::string::npos);
  CHECK(loops("far.json", R"({"loops": [{"kind": "connect", "body1": "coupler", "point1": [0.4, 1e7, 0.1], "body2": "rocker"}]})")
            .find("loops[0].point1[1]: expected a finite number of metres within ±1e6, got 10000000.0") != std::string::npos);
  CHECK(loops("huge.json", R"({"loops": [{"kind": "connect", "body1": "coupler", "point1": [0.4, 1e400, 0.1], "body2": "rocker"}]})")
            .find("not JSON") != std::string::npos);
  CHECK(loops("name.json", R"({"loops": [{"kind": "connect", "body1": 3, "point1": [0.4, 0, 0.1], "body2": "rocker"}]})")
            .find("loops[0].body1: expected a string, got 3") != std::string::npos);
  CHECK(loops("twice.json", R"({"loops": [{"name": "p", )" + good + R"(}, {"name": "p", )" + good + "}]}")
            .find("loops[1].name: 'p' names an earlier closure too") != std::string::npos);
  CHECK(loops("extra.json", R"({"loops": [{"pont2": [0, 0, 0], )" + good + "}]}").find("loops[0].pont2: unknown key") != std::string::npos);
  // Names and points the model cannot hold: the loader names the JSON path too.
  CHECK(loops("link.json", R"({"loops": [{"kind": "connect", "body1": "coupler", "point1": [0.4, 0, 0.1], "body2": "base"}]})")
            .find("loops[0].body2: expected a link of " + urdf + ", got 'base'") != std::string::npos);
  CHECK(loops("open.json", R"({"loops": [{"name": "gap", "point2": [0, 0, 0.3], )" + good + "}]}")
            .find("loops[0] ('gap') does not hold at the reference pose (gap 0.1)") != std::string::npos);
  CHECK(loops("same.json", R"({"loops": [{"kind": "weld", "body1": "rocker", "point1": [0, 0, 0], "body2": "rocker"}]})")
            .find("loops[0] ('loop0') ties body 'rocker' to 'rocker', which no joint separates") != std::string::npos);
  // Hostile bytes: deep nesting, non-UTF-8, more than a loops file is.
  CHECK(loops("deep.json", std::string(100000, '[')).find("nested deeper than 8 levels") != std::string::npos);
  CHECK(loops("latin1.json", "{\"loops\": [{\"name\": \"caf\xE9\"}]}").find("not JSON") != std::string::npos);
  const std::string big = writeFile("big.json", "{}");
  fs::resize_file(big, 2u << 20);
  CHECK(errorOf(urdf, big).find("more than 1048576 bytes") != std::string::npos);
}
