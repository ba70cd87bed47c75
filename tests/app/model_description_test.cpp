// Model descriptions (labs/generic/model_description.h, issue 42 item 4): every model file of
// assets/models, the labs' own (labs/*/ *.xml) and the mesh arm of tests/models, exported, reads back
// to the same model without MuJoCo — the same description text again, the same M(q) and bias h(q, v) at
// q0 and seeded states, bit for bit — and `dynlab run` of the description writes the same trace bytes
// (the hand engine's and Bullet's) as `dynlab run` of the file. Then the hostile descriptions: each
// malformed field one line naming the file, its JSON path and what was expected, exit 2.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <random>

#include "labs/generic/model_description.h"
#include "labs/generic/model_loops.h"
#include "physics/constrained_mechanism.h"
#include "physics/integrate.h"
#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using nlohmann::json;

namespace {

const fs::path kSource(DYNLAB_SOURCE_DIR);

// The model files: assets/models, the labs' folders, tests/models/mesh_arm (meshes).
std::vector<fs::path> modelFiles() {
  std::vector<fs::path> out;
  auto add = [&](const fs::path& dir) {
    for (const auto& e : fs::directory_iterator(dir))
      if (e.path().extension() == ".xml" || e.path().extension() == ".urdf") out.push_back(e.path());
  };
  add(kSource / "assets/models");
  for (const auto& lab : fs::directory_iterator(kSource / "labs"))
    if (lab.is_directory()) add(lab.path());
  add(kSource / "tests/models/mesh_arm");
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("every model file: its description reads back to the same text, M and h, bit for bit") {
  const auto files = modelFiles();
  CHECK(files.size() >= 12);
  bool meshes = false;
  for (const fs::path& file : files) {
    CAPTURE(file);
    const dyn::model_file::LoadedModel m = dyn::app::loadWithLoops(file.string(), "");
    const std::string text = dyn::app::descriptionText(m);
    dyn::model_file::LoadedModel d = dyn::app::readDescriptionText(text, "described.json");
    CHECK(d.compiled == nullptr);
    CHECK(d.file == "described.json");
    d.file = m.file;  // the source's name, which the description records
    CHECK(dyn::app::descriptionText(d) == text);
    for (const auto& g : d.drawing.geoms) meshes = meshes || (g.mesh && !g.mesh->triangles.empty());
    dyn::ConstrainedMechanism<dyn::Spatial> a(m.mechanism), b(d.mechanism);
    const int n = a.n();
    std::mt19937_64 rng(42);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int s = 0; s < 4; ++s) {
      dyn::VecN q = m.q0, v = dyn::VecN::Zero(n);
      for (Eigen::Index i = 0; s > 0 && i < q.size(); ++i) q[i] += 0.5 * u(rng);
      for (int i = 0; s > 0 && i < n; ++i) v[i] = u(rng);
      dyn::normalizeConfiguration(m.mechanism.tree, q);
      const dyn::MatN Ma = a.massMatrix(q), Mb = b.massMatrix(q);
      const dyn::VecN ha = a.inverseDynamics(q, v, dyn::VecN::Zero(n)), hb = b.inverseDynamics(q, v, dyn::VecN::Zero(n));
      CHECK(Ma.size() > 0);
      CHECK(std::memcmp(Ma.data(), Mb.data(), sizeof(double) * std::size_t(Ma.size())) == 0);
      CHECK(std::memcmp(ha.data(), hb.data(), sizeof(double) * std::size_t(ha.size())) == 0);
    }
  }
  CHECK(meshes);  // the mesh arm's triangles went through the description too
}

// A data lab loads its model with the joint limits read, not held (puma_motion, puma_impedance): the
// description, exported with them held, gives the same mechanism without them.
TEST_CASE("a description read as a data lab reads its model: the joint limits left out, as the file's load does") {
  const std::string file = (kSource / "assets/models/puma560.urdf").string();
  dyn::model_file::LoadOptions data;
  data.joint_limits = false;
  const dyn::model_file::LoadedModel held = dyn::app::loadWithLoops(file, ""), free = dyn::app::loadWithLoops(file, "", data);
  REQUIRE(held.contacts.size() > free.contacts.size());
  const dyn::model_file::LoadedModel d = dyn::app::readDescriptionText(dyn::app::descriptionText(held), "puma.json", data);
  const json a = dyn::app::describeModel(free), b = dyn::app::describeModel(d);
  CHECK(a["mechanism"] == b["mechanism"]);
  CHECK(a["contacts"] == b["contacts"]);
  CHECK(a["notes"].size() == b["notes"].size());
}

TEST_CASE("every model file: dynlab run of its description writes the file's trace bytes") {
  TempDir dir("model_description_runs");
  for (const fs::path& file : modelFiles()) {
    CAPTURE(file);
    const std::string desc = (dir / (file.stem().string() + ".json")).string();
    const Result e = dynlab(dir, {"model", file.string(), "--export", desc});
    CAPTURE(e.err);
    REQUIRE(e.code == 0);
    CHECK(e.out.find("wrote " + desc) == 0);
    const Result a = dynlab(dir, {"run", file.string(), "--duration", "0.3", "--out", "from_file"});
    const Result b = dynlab(dir, {"run", desc, "--duration", "0.3", "--out", "from_description"});
    CAPTURE(b.err);
    CHECK(a.code == b.code);
    for (const char* trace : {"trace.csv", "trace_bullet.csv"}) {
      CAPTURE(trace);
      const std::string ta = readFile(dir / "from_file" / trace), tb = readFile(dir / "from_description" / trace);
      CHECK(ta.size() > 100);
      CHECK(ta == tb);
    }
    fs::remove_all(dir / "from_file"), fs::remove_all(dir / "from_description");
  }
}

// A valid description (the five-bar's, a closure and its kept rows) changed in one place: each change
// is one line on stderr naming the file, the JSON path and what was expected, exit 2, nothing written.
TEST_CASE("hostile descriptions: one line naming the file, the JSON path and what was expected, exit 2") {
  TempDir dir("model_description_hostile");
  const Result e = dynlab(dir, {"model", (kSource / "assets/models/fivebar.xml").string(), "--export", "good.json"});
  REQUIRE(e.code == 0);
  const json good = json::parse(readFile(dir / "good.json"));
  struct Case {
    std::string pointer;  // JSON pointer of the changed value
    json value;           // its new value (with remove: the key removed)
    std::string at;       // the JSON path the message names
    std::string says;     // what the message must hold besides the file and the path
    bool remove = false;
  };
  const std::vector<Case> cases = {
      {"/version", 2, "/version", "expected format version 1"},
      {"/format", "something else", "/format", "expected \"dynlab model description\""},
      {"/mechanism/tree/bodies/0/parent", 5, "/mechanism/tree/bodies/0/parent", "expected an integer in [-1, -1]"},
      {"/mechanism/tree/bodies/1/parent", 18446744073709551615ull, "/mechanism/tree/bodies/1/parent", "expected an integer in [-1, 0]"},
      {"/mechanism/tree/bodies/0/inertia/35", -1.0, "/mechanism/tree/bodies/0/inertia", "spatial inertia"},
      {"/mechanism/tree/bodies/0/inertia/0", -5.0, "/mechanism/tree/bodies/0/inertia", "positive semidefinite"},
      {"/mechanism/tree/bodies/0/axis", json::array({0.0, 0.0, 2.0}), "/mechanism/tree/bodies/0/axis", "expected a unit vector"},
      {"/mechanism/tree/bodies/0/E/0", 2.0, "/mechanism/tree/bodies/0/E", "expected a rotation matrix"},
      {"/mechanism/tree/bodies/0/r/1", "x", "/mechanism/tree/bodies/0/r/1", "expected a number"},
      {"/mechanism/tree/bodies/0/r/1", 1e300, "/mechanism/tree/bodies/0/r/1", "expected a number in"},
      {"/mechanism/tree/bodies", json::array(), "/mechanism/tree/bodies", "expected an array of 1 to"},
      {"/mechanism/tree/bodies/0/joint", "ball", "/mechanism/tree/balls", "expected a ball joint"},
      {"/mechanism/constraints/0/a", 99, "/mechanism/constraints/0/a", "expected an integer in [-1, 3]"},
      {"/mechanism/constraints/0/rows", json::array({false, false, false, false, false, false}), "/mechanism/constraints/0/rows", "at least one row"},
      {"/mechanism/constraints/0/kind", "spring", "/mechanism/constraints/0/kind", "expected one of"},
      {"/mechanism/constraints", json::array(), "/closures", "expected an array of 0 elements"},
      {"/mechanism/bullet/solver_iterations", 0, "/mechanism/bullet/solver_iterations", "expected an integer in [1, 10000]"},
      {"/q0", json::array({0.0}), "/mechanism/tree/bodies", "match /q0"},
      {"/coordinates", json::array({"a"}), "/coordinates", "expected one name per entry of /q0"},
      {"/joints/0/qpos", 40, "/joints/0/qpos", "expected an integer in [0, 3]"},
      {"/joints/1/qpos", 3, "/joints/1/qpos", "expected 1, the tree body's coordinate"},
      {"/joints/1/type", "slide", "/joints/1/type", "expected the type of tree body 1's joint"},
      {"/closures/0/kept/0", "up", "/closures/0/kept/0", "expected a row name"},
      {"/start/q", json::array({0.0, 0.0}), "/start/q", "expected an array of 4 elements"},
      {"/start/q/0", 0.5, "/start/q", "expected a pose that holds the model's loops (loop closure"},
      {"/start/v/0", 1.0, "/start/v", "expected rates that keep the loops closed"},
      {"/drawing/geoms/0/rgba/0", 7.0, "/drawing/geoms/0/rgba/0", "expected a number in [0, 1]"},
      {"/timestep", "1e999", "/", "expected valid JSON"},
      {"/dof", nullptr, "/", "missing key \"dof\"", true},
      {"/extra", 1, "/extra", "unknown key"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.pointer);
    json bad = good;
    if (c.remove) bad.erase(json::json_pointer(c.pointer).back());
    else bad[json::json_pointer(c.pointer)] = c.value;
    std::string text = bad.dump(1);
    if (c.value == "1e999") text.replace(text.find("\"1e999\""), 7, "1e999");  // past a double's range: JSON holds no NaN or inf
    writeFile(dir / "bad.json", text);
    const Result r = dynlab(dir, {"run", "bad.json", "--duration", "0.1", "--out", "out"});
    CAPTURE(r.err);
    CHECK(r.code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.rfind("error: bad.json: " + c.at + ": ", 0) == 0);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "out"));
  }
}

// The description names its start: --key other than the one it was exported with, or loops given beside
// it, are refused in one line.
TEST_CASE("a description's options: --key and --loops refused in one line") {
  TempDir dir("model_description_options");
  REQUIRE(dynlab(dir, {"model", (kSource / "assets/models/fourbar.xml").string(), "--export", "fourbar.json"}).code == 0);
  const Result k = dynlab(dir, {"run", "fourbar.json", "--key", "up", "--out", "out"});
  CHECK(k.code == 2);
  CHECK(k.err.find("a description starts where it was exported") != std::string::npos);
  writeFile(dir / "loops.json", readFile(kSource / "assets/models/fourbar.loops.json"));
  const Result l = dynlab(dir, {"model", "fourbar.json", "--loops", "loops.json", "--out", "out"});
  CHECK(l.code == 2);
  CHECK(std::count(l.err.begin(), l.err.end(), '\n') == 1);
  CHECK_FALSE(fs::exists(dir / "out"));
}
