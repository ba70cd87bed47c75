// dynlab's own elements beside a model file (physics/model_file: GivenRolling, GivenContact; the JSON
// read by labs/generic/model_loops.cpp) against the labs' C++ descriptions of the same mechanisms:
//  * unicycle.xml + unicycle.loops.json and the unicycle lab's describe() (labs/unicycle), and
//  * pen.xml + pen.loops.json and the pen-on-table lab's describe() (labs/pen_on_table),
// each with its plant read from the lab's JSON, give the same M(q), h(q, v) = C v + G, constraint rows
// (φ, J, A, the bias J'θ' − A'v_c) and solve (θ'', η) at random states, to 1e-12;
// and the loader's checks on the elements: a wheel off its ground, a ball inside its plane, a body the
// file has not, a body that does not move, a name taken twice.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "labs/generic/model_loops.h"
#include "labs/pen_on_table/mechanism.h"
#include "labs/unicycle/mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
using namespace dyn::test_model_file;
namespace fs = std::filesystem;

namespace {

nlohmann::json labJson(const char* lab) {
  std::ifstream in(std::string(DYNLAB_SOURCE_DIR) + "/labs/" + lab + "/" + lab + ".json");
  return nlohmann::json::parse(in);
}

double scale(const MatN& a) { return std::max(1.0, maxAbs(a)); }

// The unicycle lab's plant as it reads unicycle.json (its inertias, when not given: m r²/2, m r²/4).
unicycle::Params unicycleParams() {
  const nlohmann::json j = labJson("unicycle")["mechanism"];
  unicycle::Params p;
  p.radius = j["radius"], p.mass = j["mass"], p.mu = j["mu"], p.gravity = j["gravity"];
  p.axle_inertia = j.value("axle_inertia", p.mass * p.radius * p.radius / 2);
  p.steer_inertia = j.value("steer_inertia", p.mass * p.radius * p.radius / 4);
  return p;
}

pen_on_table::Params penParams() {
  const nlohmann::json j = labJson("pen_on_table"), m = j["mechanism"], t = j["table"];
  pen_on_table::Params p;
  for (std::size_t i = 0; i < 3; ++i) p.links[i] = {m["links"][i]["length"], m["links"][i]["mass"], m["links"][i]["radius"]};
  p.tip_radius = m["tip_radius"], p.pen_load = m["pen_load"], p.gravity = m["gravity"];
  p.table_height = t["height"], p.table_stiffness = t["stiffness"], p.table_damping = t["damping"], p.mu = t["mu"];
  return p;
}

// The two descriptions at random states (same coordinates): M, h, each constraint's φ, J, A and bias,
// and the whole solve; the largest difference of each, relative to the size of what is compared.
struct Worst {
  double M = 0, h = 0, rows = 0, bias = 0, solve = 0;
};
Worst compare(const MechanismModel<Spatial>& file, const MechanismModel<Spatial>& lab, const VecN& q0, double spread, int trials) {
  ConstrainedMechanism<Spatial> f(file), l(lab);
  REQUIRE(f.n() == l.n());
  REQUIRE(file.constraints.size() == lab.constraints.size());
  // Unilateral rows closed in both (the solve holds them, as a touchdown does).
  for (std::size_t i = 0; i < lab.constraints.size(); ++i) {
    CHECK(std::string(file.constraints[i]->kind()) == lab.constraints[i]->kind());
    if (lab.constraints[i]->unilateral()) f.setClosed(int(i), true), l.setClosed(int(i), true);
  }
  const int n = f.n();
  Random r;
  Worst w;
  for (int trial = 0; trial < trials; ++trial) {
    const VecN q = q0 + r.vec(n, spread), v = r.vec(n, 3.0), tau = r.vec(n, 2.0);
    const MatN Ml = l.massMatrix(q);
    w.M = std::max(w.M, maxAbs(f.massMatrix(q) - Ml) / scale(Ml));
    const VecN hl = l.inverseDynamics(q, v, VecN::Zero(n));
    w.h = std::max(w.h, maxAbs(f.inverseDynamics(q, v, VecN::Zero(n)) - hl) / scale(hl));
    f.stage(q, &v);
    l.stage(q, &v);
    for (std::size_t i = 0; i < lab.constraints.size(); ++i) {
      const int rows = lab.constraints[i]->rows();
      VecN phif = VecN::Zero(rows), phil = VecN::Zero(rows), bf = VecN::Zero(rows), bl = VecN::Zero(rows);
      MatN Jf = MatN::Zero(rows, n), Jl = MatN::Zero(rows, n), Af = MatN::Zero(rows, 0), Al = MatN::Zero(rows, 0);
      file.constraints[i]->position(f.kinematics(), 0, phif, Jf, Af);
      lab.constraints[i]->position(l.kinematics(), 0, phil, Jl, Al);
      file.constraints[i]->bias(f.kinematics(), 0, bf);
      lab.constraints[i]->bias(l.kinematics(), 0, bl);
      w.rows = std::max({w.rows, maxAbs(phif - phil), maxAbs(Jf - Jl) / scale(Jl)});
      w.bias = std::max(w.bias, maxAbs(bf - bl) / scale(bl));
    }
    const auto sf = f.solve(q, v, tau), sl = l.solve(q, v, tau);
    w.solve = std::max({w.solve, maxAbs(sf.qdd - sl.qdd) / scale(sl.qdd), maxAbs(sf.eta - sl.eta) / scale(sl.eta)});
  }
  MESSAGE("|ΔM| " << w.M << ", |Δh| " << w.h << ", |Δφ|, |ΔJ| " << w.rows << ", |Δ(J'θ')| " << w.bias << ", |Δθ''|, |Δη| " << w.solve);
  return w;
}

// Every quantity compare() measures agrees to rounding (1e-12).
void checkEqual(const Worst& w) {
  CHECK(w.M < 1e-12);
  CHECK(w.h < 1e-12);
  CHECK(w.rows < 1e-12);
  CHECK(w.bias < 1e-12);
  CHECK(w.solve < 1e-12);
}

std::string writeJson(const std::string& name, const std::string& text) {
  static const fs::path dir = scratchFolder("model_file_elements_test");
  return writeFile(dir, name, text).string();
}

// The loader's one line for a model with the given JSON beside it ("" if it loads).
std::string errorOf(const char* file, const std::string& json) {
  try {
    app::loadWithLoops(model(file), writeJson("beside.json", json));
  } catch (const model_file::ModelFileError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("unicycle.xml + its rolling element equals the unicycle lab's C++ description (M, h, rows, bias, solve; 1e-12)") {
  const model_file::LoadedModel file = app::loadWithLoops(model("unicycle.xml"), "");
  REQUIRE(file.contacts.size() == 1);
  CHECK(file.contacts[0].kind == "rolling");
  CHECK(file.dof == 2);  // five coordinates, three rolling rows: the heading and spin rates stay free
  // The file's coordinates are the lab's one to one: x, y, z (the centre), heading, spin.
  std::vector<std::string> names;
  for (const auto& j : file.joints) names.push_back(j.name);
  CHECK(names == std::vector<std::string>{"x", "y", "z", "heading", "spin"});
  const unicycle::Params p = unicycleParams();
  VecN q0(5), v0(5);
  unicycle::Mechanism(p).state(0, 0, 0, 0, 0, 0, q0, v0);
  CHECK(maxAbs(file.q0 - q0) < 1e-15);  // the wheel written on the ground at the lab's start
  checkEqual(compare(file.mechanism, unicycle::describe(p), q0, 2.0, 40));
}

TEST_CASE("pen.xml + its contact element equals the pen-on-table lab's C++ description (M, h, rows, bias, solve; 1e-12)") {
  const model_file::LoadedModel file = app::loadWithLoops(model("pen.xml"), "");
  REQUIRE(file.contacts.size() == 1);
  CHECK(file.contacts[0].kind == "plane_contact");
  CHECK(file.dof == 3);  // the contact is one-sided: not counted
  const pen_on_table::Params p = penParams();
  checkEqual(compare(file.mechanism, pen_on_table::describe(p), VecN::Zero(3), 2.0, 40));
}

TEST_CASE("the comparison can fail: a wheel 1 mm larger or a tip 1 mm off is seen") {
  unicycle::Params big = unicycleParams();
  big.radius += 1e-3;
  big.axle_inertia = unicycleParams().axle_inertia, big.steer_inertia = unicycleParams().steer_inertia;
  const model_file::LoadedModel wheel = app::loadWithLoops(model("unicycle.xml"), "");
  const Worst a = compare(wheel.mechanism, unicycle::describe(big), wheel.q0, 2.0, 5);
  CHECK(std::max(a.rows, a.bias) > 1e-4);
  pen_on_table::Params longer = penParams();
  longer.links[2].length += 1e-3;
  const Worst b = compare(app::loadWithLoops(model("pen.xml"), "").mechanism, pen_on_table::describe(longer), VecN::Zero(3), 2.0, 5);
  CHECK(std::max({b.M, b.rows, b.solve}) > 1e-5);
}

TEST_CASE("the loader refuses elements that do not fit the file, in one line naming the JSON path") {
  const std::string wheel = R"({"rolling": [{"name": "w", "body": "wheel", "axle": [0, 1, 0], "radius": RADIUS}]})";
  auto with = [&](const std::string& radius) { return std::string(wheel).replace(wheel.find("RADIUS"), 6, radius); };
  CHECK(errorOf("unicycle.xml", with("0.1")).empty());
  const std::string off = errorOf("unicycle.xml", with("0.12"));
  CHECK(off.find("rolling[0]") != std::string::npos);
  CHECK(off.find("not on its ground") != std::string::npos);
  CHECK(off.find('\n') == std::string::npos);
  const std::string inside =
      errorOf("pen.xml", R"({"contacts": [{"name": "tip", "body": "fore", "point": [0.35, 0, 0], "radius": 0.005, "height": 0.31}]})");
  CHECK(inside.find("contacts[0]") != std::string::npos);
  CHECK(inside.find("inside its plane") != std::string::npos);
  CHECK(errorOf("pen.xml", R"({"contacts": [{"body": "hand", "point": [0, 0, 0]}]})").find("contacts[0].body: expected a body") != std::string::npos);
  CHECK(errorOf("pen.xml", R"({"contacts": [{"body": "world", "point": [0, 0, 0]}]})").find("does not move") != std::string::npos);
  CHECK(errorOf("pen.xml", R"({"contacts": [{"name": "a", "body": "fore", "point": [0, 0, 0]}, {"name": "a", "body": "upper", "point": [0, 0, 0]}]})")
            .find("contacts[1].name") != std::string::npos);
  // A rolling wheel needs a ground under it: its kind rolls on z = height only; the axle may be any.
  CHECK(errorOf("unicycle.xml", R"({"rolling": [{"body": "wheel", "axle": [0, 0, 0], "radius": 0.1}]})").find("rolling[0].axle") != std::string::npos);
}
