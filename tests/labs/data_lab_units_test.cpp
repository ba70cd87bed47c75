// Units and frames of a data lab (labs/generic), on a scratch cart-pole written in the test (a slide
// "cart" along x carrying a hinge "pole" about y):
//  * a slide actuator's force is in N and a hinge's torque in N·m, in the trace's units and the overlay;
//    a slide's start or joint path in degrees is refused (one line naming it), in metres accepted; a
//    metric of a slide's force documented in N·m is refused at its metric_docs unit;
//  * tool.at and payloads.at are world coordinates at the model file's pose, carried with their body
//    (not the lab's start pose): the tool's first trace row is where the body took that point, and a
//    payload written beside the horizontal pole hangs under the hinge once the pole starts hanging;
//  * a task path out of the mechanism's reach is refused when the lab is read, naming the segment and
//    the point: in the parser and by the dynlab command (exit 2, one line).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "labs/generic/data_lab.h"
#include "labs/settings.h"
#include "tests/app/cli_run.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

// The pole is horizontal (+x) at the file's pose, 0.5 m, 0.5 kg at its middle; the cart 1 kg.
const char* kModel = R"(<mujoco model="cart_pole">
  <option gravity="0 0 -9.81" timestep="0.001"/>
  <default><geom contype="0" conaffinity="0" mass="0"/></default>
  <worldbody>
    <body name="cart">
      <joint name="cart" type="slide" axis="1 0 0"/>
      <inertial pos="0 0 0" mass="1.0" diaginertia="0.01 0.01 0.01"/>
      <geom type="box" size="0.1 0.05 0.03"/>
      <body name="pole">
        <joint name="pole" type="hinge" axis="0 1 0"/>
        <inertial pos="0.25 0 0" mass="0.5" diaginertia="0.0001 0.0105 0.0105"/>
        <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.01"/>
      </body>
    </body>
  </worldbody>
</mujoco>
)";

// The lab: both joints actuated, the tool at the pole's tip written at the file's pose.
json cartPole() {
  return json::parse(R"({
    "title": "Cart-pole: units and frames",
    "model_file": "cart_pole.xml",
    "actuated": ["cart", "pole"],
    "torque_limit": [50.0, 20.0],
    "tool": {"body": "pole", "at": [0.5, 0.0, 0.0], "axes": ["x", "z"]},
    "initial": {"actuated": [0.1, 1.5707963267948966]},
    "trajectory": {"segments": [{"hold": 0.1}]},
    "simulation": {"dt": 0.001, "duration": 0.2, "integrator": "rk4", "drift": "none"},
    "controller": {"kind": "none", "control_period": 0.001},
    "gains": {}
  })");
}

struct Folder {
  fs::path path = fs::temp_directory_path() / ("dynlab_units_" + std::to_string(::getpid()));
  Folder() {
    fs::create_directories(path);
    std::ofstream(path / "cart_pole.xml") << kModel;
  }
  ~Folder() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

generic::DataSettings parse(const json& c, const Folder& f) {
  return generic::parseDataSettings(JsonView(c, (f.path / "cart_pole.json").string()), "cart_pole", f.path.string());
}

Trace run(const generic::DataLab& lab) {
  Trace tr;
  tr.columns = lab.columns();
  auto sim = lab.simulate(Engine::Hand);
  std::vector<double> row;
  while (sim->step(row)) tr.append(row);
  return tr;
}

// The error a config is refused with (empty: accepted).
std::string refusal(const json& c, const Folder& f, std::string* path = nullptr) {
  try {
    parse(c, f);
  } catch (const InputError& e) {
    if (path) *path = e.path();
    return e.what();
  }
  return {};
}

bool endsWith(const std::string& s, const std::string& tail) { return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0; }

}  // namespace

TEST_CASE("a slide actuator's force is in N, a hinge's torque in N·m: trace units and the overlay") {
  const Folder f;
  const generic::DataLab lab(parse(cartPole(), f));
  CHECK(lab.unit("tau_cart") == "N");
  CHECK(lab.unit("tau_pole") == "N·m");
  CHECK(lab.unit("q_cart") == "m");
  CHECK(lab.unit("q_pole") == "rad");
  CHECK(lab.agreementUnit("max_dq") == "rad, m");
  const Trace tr = run(lab);
  REQUIRE(tr.rows() > 10);
  Overlay o;
  lab.overlay(tr, 10, o);
  int seen = 0;
  for (const auto& [label, value] : o.lines) {
    INFO(label, ": ", value);
    if (label == "τ cart") {
      CHECK(endsWith(value, " N"));
      ++seen;
    }
    if (label == "τ pole") {
      CHECK(endsWith(value, " N·m"));
      ++seen;
    }
  }
  CHECK(seen == 2);
}

TEST_CASE("a slide's start and joint path are refused in degrees, taken in metres") {
  const Folder f;
  json c = cartPole();
  c["initial"] = {{"actuated_deg", {0.0, 90.0}}};
  std::string path;
  std::string why = refusal(c, f, &path);
  CHECK(path == "/initial/actuated_deg/0");
  CHECK(why.find("cart is a slide") != std::string::npos);
  CHECK(why.find("/initial/actuated") != std::string::npos);
  CHECK(why.find('\n') == std::string::npos);
  // A metric of the cart's force documented in N·m (as a lab copied from a hinged one would say) is
  // refused at its unit; in N it is taken.
  c = cartPole();
  c["metrics"] = {{"cart_peak", {{"of", "tau_cart"}, {"stat", "max_abs"}}}, {"pole_peak", {{"of", "tau_pole"}, {"stat", "max_abs"}}}};
  c["metric_docs"] = {{"cart_peak", {{"unit", "N·m"}}}, {"pole_peak", {{"unit", "N·m"}}}};
  why = refusal(c, f, &path);
  CHECK(path == "/metric_docs/cart_peak/unit");
  CHECK(why.find("slide actuators' forces (N)") != std::string::npos);
  c["metric_docs"]["cart_peak"]["unit"] = "N";
  CHECK(refusal(c, f) == "");
  c = cartPole();
  c["initial"] = {{"actuated_deg", {0.0, 90.0}}};
  // Both spellings at once: which one is meant is unclear.
  c["initial"] = {{"actuated_deg", {0.0, 90.0}}, {"actuated", {0.0, 1.0}}};
  CHECK(refusal(c, f, &path).find("not both") != std::string::npos);
  // A joint path: move_deg moves hinges only; move takes each joint's own unit.
  c = cartPole();
  c["controller"]["kind"] = "joint_pd_gravity";
  c["gains"] = json::parse(R"({"kp": {"value": 100, "min": 0, "max": 1e4}, "kd": {"value": 10, "min": 0, "max": 1e3}})");
  c["trajectory"] = json::parse(R"({"space": "joint", "segments": [{"move_deg": [5.0, 80.0], "time": 0.1}]})");
  why = refusal(c, f, &path);
  CHECK(path == "/trajectory/segments/0/move_deg");
  CHECK(why.find("cart is a slide") != std::string::npos);
  c["trajectory"] = json::parse(R"({"space": "joint", "segments": [{"move": [0.2, 1.4], "time": 0.1}]})");
  CHECK(refusal(c, f) == "");
  const generic::DataLab lab(parse(c, f));
  CHECK(lab.unit("e_cart") == "m");
  CHECK(lab.unit("e_pole") == "rad");
}

TEST_CASE("tool.at and payloads.at are world coordinates at the model file's pose, carried by their body") {
  const Folder f;
  json c = cartPole();
  // A 1 kg payload written where the tool is: at the file's pose, the pole's tip (0.5, 0, 0).
  c["plant"] = {{"payloads", {{{"body", "pole"}, {"at", {0.5, 0.0, 0.0}}, {"mass", 1.0}}}}};
  const generic::DataLab lab(parse(c, f));
  const Trace tr = run(lab);
  REQUIRE(tr.rows() > 100);
  // The start turns the pole by 90° about y (x to −z) and moves the cart 0.1 m: the tool is at
  // (0.1, −0.5), not at (0.5, 0) where "at" was written.
  CHECK(tr.at(0, "tool_x") == doctest::Approx(0.1).epsilon(1e-12));
  CHECK(tr.at(0, "tool_z") == doctest::Approx(-0.5).epsilon(1e-12));
  // The payload went with the pole: it hangs under the hinge, so nothing moves without torques (written
  // at the start pose instead, it would sit 0.5 m beside the hinge and swing the pole down).
  double worst = 0;
  for (std::size_t r = 0; r < tr.rows(); ++r)
    worst = std::max({worst, std::abs(tr.at(r, "q_pole") - M_PI / 2), std::abs(tr.at(r, "q_cart") - 0.1)});
  MESSAGE("hanging payload: largest motion " << worst);
  CHECK(worst < 1e-9);
}

TEST_CASE("a task path out of the mechanism's reach is refused when the lab is read, naming the point") {
  const Folder f;
  json c = cartPole();
  // The tool (the pole's tip) stays within 0.5 m of the cart's rail (z = 0): z = −0.7 is out of reach.
  // (The pole starts at 1 rad, not hanging straight down, where the tool could not move along z.)
  c["initial"]["actuated"] = {0.1, 1.0};
  c["controller"]["kind"] = "task_pd_gravity";
  c["gains"] = json::parse(R"({"kp": {"value": 100, "min": 0, "max": 1e4}, "kd": {"value": 10, "min": 0, "max": 1e3}})");
  c["trajectory"] = json::parse(R"({"segments": [{"hold": 0.05}, {"move": [0.2, -0.3], "time": 0.05}, {"move": [0.3, -0.7], "time": 0.1}]})");
  std::string path;
  const std::string why = refusal(c, f, &path);
  INFO(why);
  CHECK(path == "/trajectory/segments/2/move");
  CHECK(why.find("out of the mechanism's reach") != std::string::npos);
  CHECK(why.find("on the way to (0.3, -0.7)") != std::string::npos);
  CHECK(why.find("(x, z) = (") != std::string::npos);
  CHECK(why.find('\n') == std::string::npos);
  // Within reach, the same path is taken.
  c["trajectory"]["segments"][2]["move"] = {0.3, -0.4};
  CHECK(refusal(c, f) == "");

  // The dynlab command: exit 2, one line naming the file, the segment and the point, before any run.
  using namespace dyn::test::cli;
  const TempDir dir("reach");
  json far = loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar/fivebar.json");
  far["trajectory"]["segments"][1]["move"] = {0.9, 0.3};
  writeFile(dir / "far.json", far.dump());
  const Result r = dynlab(dir, {"run", "fivebar", "--config", "far.json", "--engine", "hand", "--out", "out"});
  INFO(r.err);
  CHECK(r.code == 2);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.find("far.json: /trajectory/segments/1/move: the point (x, z) = (") != std::string::npos);
  CHECK(r.err.find("on the way to (0.9, 0.3) is out of the mechanism's reach") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out" / "trace_hand.csv"));
}
