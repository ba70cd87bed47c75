// The pieces of a lab without C++ (labs/generic, labs/controllers), against closed forms:
//  * the task path: continuous to the acceleration at every segment's ends, x' and x'' equal central
//    differences of x and x', a circle keeps its radius and one turn returns to its start;
//  * metrics as data: each statistic on a trace with known values;
//  * task-space inverse dynamics on the five-bar with the exact model: the tool's error follows the
//    closed form of e'' + 2ζω e' + ω² e = 0, the deviation first order in the control period (its hold);
//  * a data lab's JSON: every bad field a one-line error naming its JSON path;
//  * a joint path: quintic moves in degrees ending at rest on their targets, derivatives by differences;
//  * on the PUMA 560 (its URDF) with joint paths fed to the joint laws: PD + gravity with the exact
//    model converges to the reference; computed torque under a payload its model lacks settles at
//    e = M̂⁻¹ΔG / ω_n² (the closed form of its static error);
//  * the joint path's and joint_scale's bad fields, one line each naming the JSON path;
//  * a push on the tool as data (environment.force): both engines deflect the five-bar's pin under task
//    PD + gravity by the closed form F/K_p; its bad fields, the target's, the impedance laws' (posture,
//    force noise, m_imp) name their path.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "labs/controllers/controller.h"
#include "labs/generic/data_lab.h"
#include "labs/generic/metric_spec.h"
#include "labs/generic/task_path.h"
#include "labs/run.h"
#include "labs/settings.h"
#include "physics/model_file/model_file.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

json fivebarConfig() { return loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar/fivebar.json"); }
json pumaConfig() { return loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/puma_motion/puma_motion.json"); }

VecN vec(std::initializer_list<double> x) {
  VecN v(Eigen::Index(x.size()));
  int i = 0;
  for (double e : x) v[i++] = e;
  return v;
}


// A bad field: a JSON merge patch of a lab's config, the JSON path its error must name, and a phrase it must say.
struct Case {
  const char* patch;
  const char* path;
  const char* says;
};

// Each case patched into `config` is refused with one line naming its path and saying its phrase.
void checkRefused(const json& config, const std::vector<Case>& cases, const std::string& file, const std::string& lab,
                  const std::string& folder) {
  for (const Case& c : cases) {
    INFO(std::string(c.patch));
    const json patched = mergePatch(config, json::parse(c.patch));
    try {
      generic::parseDataSettings(JsonView(patched, file), lab, folder);
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string what = e.what();
      CHECK(e.path() == c.path);
      CHECK(what.find(c.says) != std::string::npos);
      CHECK(what.find('\n') == std::string::npos);
    }
  }
}
}  // namespace

TEST_CASE("task path: smooth joins, derivatives by differences, a circle's radius and its closing") {
  const json j = json::parse(R"J({"segments": [{"hold": 0.2}, {"move": [0.0, 0.4], "time": 0.5},
                                 {"circle": [0.0, 0.5], "turns": 1.0, "time": 1.5}, {"hold": 0.5}]})J");
  const VecN start = vec({0.0, 0.53});
  const generic::TaskPath path(JsonView(j, "path.json", "/trajectory"), start, 10);
  CHECK(path.duration() == doctest::Approx(2.7));
  VecN x, xd, xdd, xp, xm, xdp, xdm, d1, d2;
  // At each join the path rests: velocity and acceleration zero, position continuous.
  for (double t : {0.2, 0.7, 2.2}) {
    path.at(t - 1e-9, xm, xdm, d1);
    path.at(t + 1e-9, xp, xdp, d2);
    CHECK((xp - xm).norm() < 1e-8);
    CHECK(xdm.norm() < 1e-6);
    CHECK(xdp.norm() < 1e-6);
  }
  // Derivatives against central differences inside segments.
  const double h = 1e-5;
  for (double t : {0.33, 0.61, 0.9, 1.45, 2.05}) {
    path.at(t, x, xd, xdd);
    path.at(t + h, xp, xdp, d1);
    path.at(t - h, xm, xdm, d2);
    CHECK(((xp - xm) / (2 * h) - xd).norm() < 1e-7);
    CHECK(((xdp - xdm) / (2 * h) - xdd).norm() < 1e-5);
  }
  // The circle: radius 0.1 about (0, 0.5) throughout; one turn ends where it began.
  for (double t = 0.7; t <= 2.2; t += 0.05) {
    path.at(t, x, xd, xdd);
    CHECK((x - vec({0.0, 0.5})).norm() == doctest::Approx(0.1).epsilon(1e-12));
  }
  path.at(2.6, x, xd, xdd);
  CHECK((x - vec({0.0, 0.4})).norm() < 1e-12);
  // Before the start it holds the start; after the end, the end.
  path.at(0.0, x, xd, xdd);
  CHECK(x == start);
  path.at(99.0, x, xd, xdd);
  CHECK((x - vec({0.0, 0.4})).norm() < 1e-12);

  // A circle needs two axes; an unknown segment names what is expected.
  const json one = json::parse(R"({"segments": [{"circle": [0.0, 0.5], "turns": 1, "time": 1}]})");
  CHECK_THROWS_WITH_AS(generic::TaskPath(JsonView(one, "p.json", "/trajectory"), vec({0.3}), 10), doctest::Contains("/trajectory/segments/0/circle"), InputError);
  const json odd = json::parse(R"({"segments": [{"spiral": 1}]})");
  CHECK_THROWS_WITH_AS(generic::TaskPath(JsonView(odd, "p.json", "/trajectory"), vec({0.3, 0.1}), 10), doctest::Contains("expected a segment"), InputError);
}

TEST_CASE("metrics as data: each statistic on a trace with known values") {
  Trace tr;
  tr.columns = {"t", "a", "b"};
  // a = 3, −4, 0.5, 0.2, 0.1 ; b = 4, 3, 0, 0, 0 at t = 0 .. 0.4
  const double a[] = {3, -4, 0.5, 0.2, 0.1}, b[] = {4, 3, 0, 0, 0};
  for (int i = 0; i < 5; ++i) tr.append({0.1 * i, a[i], b[i]});
  const json spec = json::parse(R"({
    "rms": {"of": "a", "stat": "rms"}, "norm_max": {"of": ["a", "b"], "stat": "max"}, "min": {"of": "a", "stat": "min"},
    "max_abs": {"of": "a", "stat": "max_abs"}, "final": {"of": "a", "stat": "final", "to": 0.25},
    "mean": {"of": "a", "stat": "mean", "from": 0.15}, "variation": {"of": ["a", "b"], "stat": "variation"},
    "settling": {"of": "a", "stat": "settling", "band": 0.6}})");
  const auto m = generic::parseMetrics(JsonView(spec, "lab.json", "/metrics"), tr.columns, 0.5, 0.1);  // 5 rows of 0.1 s
  auto value = [&](const char* k) { return generic::evaluate(m.at(k), tr); };
  CHECK(value("rms") == doctest::Approx(std::sqrt((9 + 16 + 0.25 + 0.04 + 0.01) / 5.0)));
  CHECK(value("norm_max") == doctest::Approx(5.0));  // |(3, 4)| = |(−4, 3)| = 5
  CHECK(value("min") == -4);
  CHECK(value("max_abs") == 4);
  CHECK(value("final") == 0.5);  // the last row with t ≤ 0.25
  CHECK(value("mean") == doctest::Approx((0.5 + 0.2 + 0.1) / 3));
  CHECK(value("variation") == doctest::Approx((7 + 4.5 + 0.3 + 0.1) + (1 + 3)));
  CHECK(value("settling") == doctest::Approx(0.2));  // within ±0.6 from t = 0.2 on
  // A column the trace lacks, and a band where none belongs.
  const json bad = json::parse(R"({"e": {"of": ["a", "zz"], "stat": "rms"}})");
  CHECK_THROWS_WITH_AS(generic::parseMetrics(JsonView(bad, "lab.json", "/metrics"), tr.columns, 0.5, 0.1), doctest::Contains("/metrics/e/of"), InputError);
  // ... naming the columns it has, so the lecturer need not look them up.
  std::string has;
  for (const auto& c : tr.columns) has += (has.empty() ? "" : ", ") + c;
  const std::string says = "expected one of this lab's trace columns (" + has + "), not \"zz\"";
  CHECK_THROWS_WITH_AS(generic::parseMetrics(JsonView(bad, "lab.json", "/metrics"), tr.columns, 0.5, 0.1),
                       doctest::Contains(says.c_str()), InputError);
  const json band = json::parse(R"({"e": {"of": "a", "stat": "rms", "band": 1}})");
  CHECK_THROWS_WITH_AS(generic::parseMetrics(JsonView(band, "lab.json", "/metrics"), tr.columns, 0.5, 0.1), doctest::Contains("/metrics/e/band"), InputError);
  // A window must hold a sample of the run: a start past its last row, an end past its end, an empty one.
  for (const char* window : {R"("from": 0.45)", R"("from": -0.1)", R"("to": 0.6)", R"("from": 0.2, "to": 0.25)"}) {
    CAPTURE(window);
    const json w = json::parse(std::string(R"({"e": {"of": "a", "stat": "rms", )") + window + "}}");
    CHECK_THROWS_WITH_AS(generic::parseMetrics(JsonView(w, "lab.json", "/metrics"), tr.columns, 0.5, 0.1), doctest::Contains("the run lasts 0.5 s"),
                         InputError);
  }
  // A run stopped early leaves a window without a sample: NaN, which no threshold credits (was 0: full marks for an RMS).
  Trace early;
  early.columns = tr.columns;
  early.append({0.0, 3, 4});
  CHECK(std::isnan(generic::evaluate(m.at("mean"), early)));
}

TEST_CASE("task inverse dynamics on the five-bar: the error follows e'' + 2ζω e' + ω² e = 0") {
  const auto file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar/fivebar.xml");
  const std::vector<int> act{0, 2};
  controllers::TaskPoint tool{file.closures[0].link1, file.closures[0].point1, {3, 5}};
  const double w = 30.0, zeta = 0.5, T = 0.25;
  // The largest deviation of |e| from the closed form over T, controlled every dt.
  auto deviation = [&](double dt) {
    controllers::Spec spec;
    spec.kind = controllers::Kind::TaskInverseDynamics;
    spec.period = dt, spec.omega_n = w, spec.zeta = zeta;
    spec.torque_limit = VecN::Constant(2, 1e4);
    controllers::Controller ctl(spec, file.mechanism, act, tool, file.q0, dt);
    ConstrainedMechanism<Spatial> plant(file.mechanism);
    VecN q = file.q0, v = VecN::Zero(4), x0;
    ctl.taskPosition(q, x0);
    // A step of the reference: (1 cm, −0.5 cm) from where the tool rests.
    const VecN e0 = vec({0.01, -0.005});
    controllers::Reference ref{x0 + e0, VecN::Zero(2), VecN::Zero(2)};
    StepOptions opt;
    opt.dt = dt;
    opt.drift.kind = Drift::Projection;
    const double wd = w * std::sqrt(1 - zeta * zeta);
    double worst = 0;
    const long steps = std::lround(T / dt);
    for (long k = 0; k <= steps; ++k) {
      const double t = double(k) * dt;
      VecN x;
      ctl.taskPosition(q, x);
      const VecN closed = e0 * std::exp(-zeta * w * t) * (std::cos(wd * t) + zeta * w / wd * std::sin(wd * t));
      worst = std::max(worst, ((ref.x - x) - closed).norm());
      const VecN tau = ctl.torque(t, q, v, ref);
      REQUIRE(step(plant, opt, tau, q, v));
    }
    return worst / e0.norm();
  };
  const double coarse = deviation(4e-4), fine = deviation(2e-4);
  MESSAGE("deviation from the closed form: " << coarse << " at 0.4 ms, " << fine << " at 0.2 ms (of |e0|)");
  CHECK(coarse < 0.02);
  // The deviation is the zero-order hold's: first order in the control period.
  CHECK(coarse / fine == doctest::Approx(2.0).epsilon(0.15));
}

TEST_CASE("a data lab's JSON: each bad field is one line naming its path") {
  const fs::path dir = fs::temp_directory_path() / ("dynlab_data_lab_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  fs::copy_file(std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar/fivebar.xml", dir / "fivebar.xml");
  std::ofstream(dir / "broken.xml") << "<mujoco><worldbody><body";
  fs::copy_file(std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/ball_loop.xml", dir / "ball_loop.xml");
  const std::vector<Case> cases = {
      {R"({"model_file": "../fivebar.xml"})", "/model_file", "without \"..\""},
      {R"({"model_file": "/etc/passwd"})", "/model_file", "relative path"},
      {R"({"model_file": "broken.xml"})", "/model_file", "a model file dynlab reads"},
      {R"({"model_file": "missing.xml"})", "/model_file", "not found"},
      // A ball joint's quaternion is no angle a controller reads: the line names the command that runs it.
      {R"({"model_file": "ball_loop.xml"})", "/model_file", "run the file with `dynlab model` or `dynlab run`"},
      {R"({"actuated": ["left_crank", "nope"]})", "/actuated/1", "left_crank, left_elbow, right_crank, right_elbow"},
      {R"({"actuated": ["left_crank", "left_crank"]})", "/actuated/1", "each joint once"},
      {R"({"torque_limit": [1.0]})", "/torque_limit", ""},
      {R"({"tool": {"closure": "pin_X", "axes": ["x", "z"]}})", "/tool/closure", "pin_C"},
      {R"({"tool": {"closure": null, "body": "nobody", "at": [0, 0, 0], "axes": ["x"]}})", "/tool/body", "left_crank"},
      {R"({"tool": {"closure": "pin_C", "axes": ["w"]}})", "/tool/axes/0", ""},
      {R"({"tool": {"closure": "pin_C", "axes": ["x", "x"]}})", "/tool/axes/1", "each axis once"},
      {R"({"initial": {"actuated_deg": [1000.0, 0.0]}})", "/initial/actuated_deg/0", ""},
      {R"({"controller": {"kind": "magic"}})", "/controller/kind", "task_inverse_dynamics"},
      {R"({"controller": {"control_period": 0.0015}})", "/controller/control_period", "whole multiple"},
      {R"({"controller": {"joint_scale": [1.0]}})", "/controller/joint_scale", ""},
      {R"({"controller": {"joint_scale": [1.0, -2.0]}})", "/controller/joint_scale/1", ""},
      {R"({"controller": {"anti_windup": "hope"}})", "/controller/anti_windup", "back_calculation"},
      {R"({"controller": {"tracking_time": 0}})", "/controller/tracking_time", ""},
      {R"({"controller": {"coulomb_compensation": "yes"}})", "/controller/coulomb_compensation", ""},
      {R"({"gains": {"omega_n": null}})", "/gains", "omega_n"},
      {R"({"metrics": {"e_rms": {"of": ["e_y"], "stat": "rms"}}})", "/metrics/e_rms/of", "e_y"},
      {R"({"plant": {"payloads": [{"body": "left_link", "at": [0, 0, 0.5], "mass": -1}]}})", "/plant/payloads/0/mass", ""},
  };
  checkRefused(fivebarConfig(), cases, "fivebar.json", "fivebar", dir.string());
  // The shipped config parses, with its columns.
  const auto s = generic::parseDataSettings(JsonView(fivebarConfig(), "fivebar.json"), "fivebar", dir.string());
  CHECK(s.columns.front() == "t");
  CHECK(std::find(s.columns.begin(), s.columns.end(), "f_pin_C_z") != s.columns.end());
  // The file's actuators: a motor names its joint in /actuated; a servo, whose law the lab would not apply, is refused.
  std::ifstream in(dir / "fivebar.xml");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t end = text.rfind("</mujoco>");
  REQUIRE(end != std::string::npos);
  std::ofstream(dir / "motor.xml") << text.substr(0, end) + "<actuator><motor name=\"left_motor\" joint=\"left_crank\"/></actuator></mujoco>";
  std::ofstream(dir / "servo.xml") << text.substr(0, end) + "<actuator><position name=\"lift\" joint=\"left_crank\" kp=\"10\"/></actuator></mujoco>";
  const json motor = mergePatch(fivebarConfig(), json::parse(R"({"model_file": "motor.xml", "actuated": ["left_motor", "right_crank"]})"));
  CHECK(generic::parseDataSettings(JsonView(motor, "fivebar.json"), "fivebar", dir.string()).actuated_names[0] == "left_crank");
  checkRefused(fivebarConfig(), {{R"({"model_file": "servo.xml"})", "/model_file", "actuator 'lift' is a servo"}}, "fivebar.json", "fivebar",
               dir.string());
  fs::remove_all(dir);
}

TEST_CASE("a data lab folder registers under its name, which must be a plain identifier") {
  const fs::path root = fs::temp_directory_path() / ("dynlab_data_reg_" + std::to_string(::getpid()));
  fs::remove_all(root);
  auto make = [&](const std::string& name) {
    fs::create_directories(root / name);
    json c = fivebarConfig();
    c["lab"] = name;
    c["model_file"] = "assets/models/fivebar.xml";  // a shipped model, from the dynlab tree
    // (Another five-bar: the lab's circle would take it within 2e-4 of a singular pose, refused when
    // read (labs/generic/reach.h); this test is about the folder, so the tool holds still.)
    c["trajectory"] = {{"segments", {{{"hold", 0.5}}}}};
    std::ofstream(root / name / (name + ".json")) << c.dump();
    return (root / name).string();
  };
  std::string why;
  CHECK_FALSE(generic::registerDataLab(make("Bad Name"), &why));
  CHECK(why.find("lowercase letters") != std::string::npos);
  // A folder with C++ in it is a C++ lab's, not a data lab.
  const std::string cpp = make("with_code");
  std::ofstream(fs::path(cpp) / "lab.cpp") << "// a C++ lab\n";
  CHECK_FALSE(generic::registerDataLab(cpp, &why));
  CHECK(why.find("no .cpp or .h") != std::string::npos);
  // A good one registers, builds from its JSON and runs; its name cannot be taken twice.
  const std::string good = make("scratch_data_lab");
  REQUIRE(generic::registerDataLab(good, &why));
  CHECK_FALSE(generic::registerDataLab(good, &why));
  CHECK(why.find("registered already") != std::string::npos);
  const LabEntry* e = findLab("scratch_data_lab");
  REQUIRE(e);
  const json config = loadJsonFile(good + "/scratch_data_lab.json");
  const auto lab = e->create(JsonView(config, good + "/scratch_data_lab.json"));
  auto sim = lab->simulate(Engine::Hand);
  std::vector<double> row;
  for (int k = 0; k < 100; ++k) REQUIRE(sim->step(row));
  const std::vector<std::string> columns = lab->columns();
  const auto at = std::find(columns.begin(), columns.end(), "constraint_residual");
  REQUIRE(at != columns.end());
  CHECK(row[std::size_t(at - columns.begin())] <= 1e-12);
  CHECK(unregisterLab("scratch_data_lab"));
  fs::remove_all(root);
}

TEST_CASE("joint path: quintic moves in degrees, at rest on their targets, derivatives by differences") {
  const json j = json::parse(R"J({"space": "joint", "segments": [{"hold": 0.2}, {"move_deg": [90.0, -45.0], "time": 0.5},
                                 {"move": [0.0, 1.0], "time": 1.0}, {"hold": 0.3}]})J");
  const VecN start = vec({0.1, -0.2});
  const generic::TaskPath path(JsonView(j, "lab.json", "/trajectory"), start, 4 * M_PI);
  CHECK(path.joint());
  CHECK(path.duration() == doctest::Approx(2.0));
  VecN x, xd, xdd, xp, xm, xdp, xdm, d1, d2;
  // Each move ends on its target (degrees converted), at rest, with no acceleration.
  path.at(0.7, x, xd, xdd);
  CHECK((x - vec({M_PI / 2, -M_PI / 4})).norm() < 1e-12);
  CHECK(xd.norm() < 1e-12);
  CHECK(xdd.norm() < 1e-9);
  path.at(1.7, x, xd, xdd);
  CHECK((x - vec({0.0, 1.0})).norm() < 1e-12);
  // Halfway through a quintic move: half the way, peak rate 15/8 Δ/T, no acceleration.
  path.at(0.45, x, xd, xdd);
  const VecN delta = vec({M_PI / 2 - 0.1, -M_PI / 4 + 0.2});
  CHECK((x - (start + 0.5 * delta)).norm() < 1e-12);
  CHECK((xd - 15.0 / 8.0 * delta / 0.5).norm() < 1e-12);
  CHECK(xdd.norm() < 1e-9);
  const double h = 1e-5;
  for (double t : {0.33, 0.61, 0.9, 1.45}) {
    path.at(t, x, xd, xdd);
    path.at(t + h, xp, xdp, d1);
    path.at(t - h, xm, xdm, d2);
    CHECK(((xp - xm) / (2 * h) - xd).norm() < 1e-7);
    CHECK(((xdp - xdm) / (2 * h) - xdd).norm() < 1e-5);
  }
  // A task path's circle is not a joint segment; "space" is task or joint.
  const json circle = json::parse(R"({"space": "joint", "segments": [{"circle": [0.0, 0.5], "turns": 1, "time": 1}]})");
  CHECK_THROWS_WITH_AS(generic::TaskPath(JsonView(circle, "p.json", "/trajectory"), start, 10), doctest::Contains("expected a joint segment"), InputError);
  const json space = json::parse(R"({"space": "cartesian", "segments": [{"hold": 1}]})");
  CHECK_THROWS_WITH_AS(generic::TaskPath(JsonView(space, "p.json", "/trajectory"), start, 10), doctest::Contains("/trajectory/space"), InputError);
}

namespace {

// The PUMA 560 from its URDF, with every joint actuated, driven toward a held joint reference from the
// stretched pose; returns the final state. `plant` may carry a payload the controller's model lacks.
VecN runPuma(const controllers::Spec& spec, const MechanismModel<Spatial>& model, const MechanismModel<Spatial>& plant,
             const VecN& q0, const VecN& ud, double T) {
  const double dt = 1e-3;
  controllers::Controller ctl(spec, model, {0, 1, 2, 3, 4, 5}, {}, q0, dt);
  ConstrainedMechanism<Spatial> mech(plant);
  VecN q = q0, v = VecN::Zero(6);
  const controllers::Reference ref{ud, VecN::Zero(6), VecN::Zero(6), true};
  StepOptions opt;
  opt.dt = dt;
  for (long k = 0; k < std::lround(T / dt); ++k) {
    const VecN tau = ctl.torque(double(k) * dt, q, v, ref);
    if (!step(mech, opt, tau, q, v)) return VecN::Constant(6, std::nan(""));  // diverged
  }
  return q;
}

}  // namespace

TEST_CASE("the PUMA 560 on a joint reference: PD + gravity converges; computed torque's payload error is M̂⁻¹ΔG/ω²") {
  const auto file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/assets/models/puma560.urdf");
  const double d = M_PI / 180;
  const VecN q0 = vec({0, 0, -90 * d, 0, 0, 0}), ud = vec({20 * d, 10 * d, -80 * d, 10 * d, 10 * d, 10 * d});
  controllers::Spec spec;
  spec.torque_limit = VecN::Constant(6, 1e4);
  // PD + gravity with the exact model: the reference is an equilibrium of the closed loop, and the
  // damping brings the arm to it (each joint's gains scaled by its inertia at the start: ω 20, ζ 1 there).
  spec.kind = controllers::Kind::JointPdGravity;
  spec.kp = 400, spec.kd = 40;
  spec.joint_scale = vec({4.26, 2.88, 0.362, 0.00164, 0.000642, 0.00004});
  const VecN q_pd = runPuma(spec, file.mechanism, file.mechanism, q0, ud, 2.0);
  MESSAGE("PD + gravity: |e| after 2 s " << (ud - q_pd).norm() << " rad from " << (ud - q0).norm());
  CHECK((ud - q_pd).norm() < 1e-5);
  // Without the scaling the light wrist (m_66 = 4e-5 kg·m²) sees kd/m_66 · dt ≫ 2 and the sampled loop
  // diverges: the scaling is what makes one pair of gains usable on every joint.
  spec.joint_scale.resize(0);
  spec.kp = 40, spec.kd = 4;
  const VecN q_raw = runPuma(spec, file.mechanism, file.mechanism, q0, ud, 0.3);
  CHECK(!((ud - q_raw).norm() < 1e-2));

  // Computed torque, a 1 kg payload at the wrist centre in the plant only: at rest τ = M̂ω²e + Ĝ must
  // equal the plant's G, so e = M̂(θ)⁻¹ (G(θ) − Ĝ(θ)) / ω² at the pose reached.
  auto plant = file;
  ConstrainedMechanism<Spatial> probe(file.mechanism);
  const Eigen::Vector3d wrist = probe.pointPosition(4, Eigen::Vector3d::Zero(), file.q0);  // joint 5's anchor: the wrist centre
  auto& b = plant.mechanism.tree.bodies[5];
  b.inertia += Spatial::inertia(1.0, wrist - probe.pointPosition(5, Eigen::Vector3d::Zero(), file.q0), Eigen::Matrix3d::Zero());
  b.central = Spatial::central(b.inertia);
  b.massless = Spatial::massless(b.inertia);
  spec.kind = controllers::Kind::ComputedTorque;
  spec.omega_n = 20, spec.zeta = 1;
  const VecN q_ct = runPuma(spec, file.mechanism, plant.mechanism, q0, ud, 3.0);
  ConstrainedMechanism<Spatial> model_mech(file.mechanism), plant_mech(plant.mechanism);
  ClosedChain<ConstrainedMechanism<Spatial>> model_chain(model_mech, {0, 1, 2, 3, 4, 5}), plant_chain(plant_mech, {0, 1, 2, 3, 4, 5});
  REQUIRE(model_chain.update(q_ct, VecN::Zero(6)));
  REQUIRE(plant_chain.update(q_ct, VecN::Zero(6)));
  const VecN predicted = model_chain.Mu().ldlt().solve(plant_chain.Gu() - model_chain.Gu()) / (20.0 * 20.0);
  const VecN e = ud - q_ct;
  MESSAGE("computed torque under the payload: e = " << e.transpose() << "\n  M̂⁻¹ΔG/ω² = " << predicted.transpose());
  CHECK(e.norm() > 1e-3);  // the payload shows
  CHECK((e - predicted).norm() < 1e-6 * e.norm() + 1e-9);
}

TEST_CASE("a joint path's JSON: each bad field is one line naming its path") {
  const std::vector<Case> cases = {
      {R"({"trajectory": {"space": "cartesian"}})", "/trajectory/space", "joint"},
      {R"({"trajectory": {"segments": [{"move_deg": [1, 2, 3], "time": 1}]}})", "/trajectory/segments/0/move_deg", ""},
      {R"({"trajectory": {"segments": [{"move_deg": [1, 2, 3, 4, 5, 1000], "time": 1}]}})", "/trajectory/segments/0/move_deg/5", ""},
      {R"({"trajectory": {"segments": [{"move_deg": [1, 2, 3, 4, 5, 6], "time": 0}]}})", "/trajectory/segments/0/time", ""},
      {R"({"trajectory": {"segments": [{"circle": [0, 0], "turns": 1, "time": 1}]}})", "/trajectory/segments/0", "joint segment"},
      {R"({"controller": {"kind": "task_pd_gravity"}})", "/trajectory/space", "task_pd_gravity"},
      {R"({"submission_options": {"kind": {"choices": ["pid", "task_inverse_dynamics"]}}})", "/trajectory/space", "task_inverse_dynamics"},
      {R"({"controller": {"joint_scale": [1, 2]}})", "/controller/joint_scale", ""},
      {R"({"controller": {"joint_scale": [1, 1, 1, 1, 1, -1]}})", "/controller/joint_scale/5", ""},
      {R"({"tool": null, "trajectory": {"space": "task"}})", "/trajectory", "tool"},
  };
  const std::string folder = std::string(DYNLAB_SOURCE_DIR) + "/labs/puma_motion";
  checkRefused(pumaConfig(), cases, "puma_motion.json", "puma_motion", folder);
  // The shipped config parses: a joint path's reference and error per actuated joint, the tool's place.
  const auto s = generic::parseDataSettings(JsonView(pumaConfig(), "puma_motion.json"), "puma_motion", folder);
  for (const char* col : {"ref_q1", "e_q6", "tool_z"}) CHECK(std::find(s.columns.begin(), s.columns.end(), col) != s.columns.end());
  CHECK(std::find(s.columns.begin(), s.columns.end(), "e_x") == s.columns.end());
  REQUIRE(s.path);
  CHECK(s.path->joint());
}

TEST_CASE("a push on the tool as data: both engines, task PD + gravity deflects by F/K_p") {
  json c = fivebarConfig();
  c["environment"] = json::parse(R"({"force": {"value": [3.0, 0.0, -2.0], "start": 0.3}})");
  c["trajectory"] = json::parse(R"({"segments": [{"hold": 2.0}]})");
  setRunDuration(c, 2.0);  // a shorter run than the exercise's (its metric windows are the exercise's)
  c["controller"]["kind"] = "task_pd_gravity";
  c["gains"]["kp"]["value"] = 2000.0;
  c["gains"]["kd"]["value"] = 40.0;
  c["target"] = json::parse(R"({"k": 500.0, "m": 1.0, "zeta": 0.7})");
  const std::string folder = std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar";
  const generic::DataLab lab(generic::parseDataSettings(JsonView(c, "fivebar.json"), "fivebar", folder));
  const auto cols = lab.columns();
  auto col = [&](const char* name) { return int(std::find(cols.begin(), cols.end(), name) - cols.begin()); };
  REQUIRE(col("push_z") < int(cols.size()));
  REQUIRE(col("dev_z") < int(cols.size()));
  CHECK(lab.unit("push_x") == "N");
  CHECK(lab.unit("target_x") == "m");
  // The target's column is the closed-form step response of M ξ'' + D ξ' + K ξ = F about the reference
  // (underdamped, from rest at the push's start), and dev is the tool minus it.
  {
    auto sim = lab.simulate(Engine::Hand);
    std::vector<double> row;
    const double K = 500, zeta = 0.7, wn = std::sqrt(K / 1.0), wd = wn * std::sqrt(1 - zeta * zeta);
    double worst = 0, dev = 0;
    while (sim->step(row)) {
      const double t = row[0] - 0.3;
      const double s = t < 0 ? 0.0 : 1 - std::exp(-zeta * wn * t) * (std::cos(wd * t) + zeta * wn / wd * std::sin(wd * t));
      const double ref_x = row[std::size_t(col("ref_x"))], ref_z = row[std::size_t(col("ref_z"))];
      worst = std::max({worst, std::abs(row[std::size_t(col("target_x"))] - (ref_x + 3.0 / K * s)),
                        std::abs(row[std::size_t(col("target_z"))] - (ref_z - 2.0 / K * s))});
      dev = std::max(dev, std::abs(row[std::size_t(col("dev_x"))] - (row[std::size_t(col("tool_x"))] - row[std::size_t(col("target_x"))])));
    }
    MESSAGE("target column against the closed form: " << worst << " m (F/K = 6e-3 m)");
    CHECK(worst < 1e-9);
    CHECK(dev < 1e-15);
  }
  // At rest J_xᵀ (K_p (x_ref − x) + F) = 0 with J_x square: x − x_ref = F / K_p, whatever the pose.
  for (Engine engine : {Engine::Hand, Engine::Bullet}) {
    auto sim = lab.simulate(engine);
    std::vector<double> row, before;
    for (int k = 0; sim->step(row); ++k)
      if (k == 250) before = row;
    const std::string name = engine == Engine::Hand ? "hand" : "Bullet";
    INFO(name);
    CHECK(before[std::size_t(col("push_x"))] == 0.0);  // not yet on at 0.25 s
    CHECK(row[std::size_t(col("push_x"))] == 3.0);
    CHECK(row[std::size_t(col("push_z"))] == -2.0);
    const double ex = row[std::size_t(col("e_x"))], ez = row[std::size_t(col("e_z"))];
    MESSAGE(name << ": e = (" << ex << ", " << ez << ") against −F/K_p = (−1.5e-3, 1e-3)");
    const double tol = engine == Engine::Hand ? 1e-8 : 2e-5;  // Bullet: its loop closure's PGS residual
    CHECK(std::abs(ex - (-3.0 / 2000.0)) < tol);
    CHECK(std::abs(ez - (2.0 / 2000.0)) < tol);
  }
  // The force sensor reads the push: impedance_inverse_dynamics programmed with the target's K, D, M
  // makes the pin follow the target's column (to the 1 ms hold's lag), in both engines; programmed with
  // another mass it does not.
  auto miss = [&](double m_imp, Engine engine) {
    json f = c;
    f["controller"]["kind"] = "impedance_inverse_dynamics";
    f["gains"]["k_imp"] = {{"value", 500.0}, {"min", 1.0}, {"max", 1e4}};
    f["gains"]["d_imp"] = {{"value", 2 * 0.7 * std::sqrt(500.0)}, {"min", 0.0}, {"max", 1e4}};
    f["gains"]["m_imp"] = {{"value", m_imp}, {"min", 0.01}, {"max", 1e4}};
    const generic::DataLab fl(generic::parseDataSettings(JsonView(f, "fivebar.json"), "fivebar", folder));
    auto sim = fl.simulate(engine);
    std::vector<double> row;
    double worst = 0;
    while (sim->step(row)) worst = std::max(worst, std::hypot(row[std::size_t(col("dev_x"))], row[std::size_t(col("dev_z"))]));
    return worst;
  };
  const double hand_miss = miss(1.0, Engine::Hand), bullet_miss = miss(1.0, Engine::Bullet), heavy_miss = miss(4.0, Engine::Hand);
  MESSAGE("force feedback: largest |tool − target| " << hand_miss << " m (Bullet " << bullet_miss << ", programmed 4 kg " << heavy_miss
                                                      << ") of |F|/K = " << std::hypot(3.0, 2.0) / 500);
  CHECK(hand_miss < 0.02 * std::hypot(3.0, 2.0) / 500);
  CHECK(bullet_miss < 0.05 * std::hypot(3.0, 2.0) / 500);
  CHECK(heavy_miss > 0.2 * std::hypot(3.0, 2.0) / 500);
  // Bad fields: one line naming the path.
  const std::vector<Case> cases = {
      {R"({"environment": {"force": {"value": [1, 2], "start": 0}}})", "/environment/force/value", ""},
      {R"({"environment": {"force": {"value": [1, 2, 1e9], "start": 0}}})", "/environment/force/value/2", ""},
      {R"({"environment": {"force": {"value": [1, 2, 3], "start": -1}}})", "/environment/force/start", ""},
      {R"({"environment": {"force": {"value": [1, 2, 3], "start": 0, "rise": "slow"}}})", "/environment/force/rise", ""},
      {R"({"environment": {"wall": {}}})", "/environment/wall", ""},
      {R"({"tool": null, "trajectory": null, "environment": {"force": {"value": [1, 2, 3], "start": 0}}})", "/environment/force", "tool"},
      {R"({"target": {"k": 0, "m": 1, "zeta": 0.7}})", "/target/k", ""},
      {R"({"target": {"k": 500, "m": 1}})", "/target", "zeta"},
      {R"({"target": {"k": 500, "m": 1, "zeta": 0.7, "d": 3}})", "/target/d", ""},
      {R"({"tool": null, "trajectory": null, "target": {"k": 500, "m": 1, "zeta": 0.7}})", "/target", "task"},
      {R"({"controller": {"posture_omega": -1}})", "/controller/posture_omega", ""},
      {R"({"controller": {"noise": {"angle": 0, "rate": 0, "seed": 1, "force": -0.5}}})", "/controller/noise/force", ""},
      {R"({"controller": {"kind": "impedance_task"}})", "/gains", "k_imp"},
      {R"({"controller": {"kind": "impedance_inverse_dynamics"}, "gains": {"k_imp": {"value": 1, "min": 0, "max": 2},
          "d_imp": {"value": 1, "min": 0, "max": 2}, "m_imp": {"value": 0, "min": 0, "max": 2}}})", "/gains/m_imp", "mass"},
  };
  checkRefused(fivebarConfig(), cases, "fivebar.json", "fivebar", folder);
}

TEST_CASE("a task path on a mechanism with a degree of freedom no actuator drives is refused as such") {
  // The five-bar has 2 degrees of freedom after its loop closes; one crank actuated leaves the other
  // free (a lecturer's trial got "reached only at a singular pose" at the path's first point).
  const std::string file = defaultConfigPath("fivebar");
  json c = loadJsonFile(file);
  c["actuated"] = {"left_crank"};
  c["torque_limit"] = {30.0};
  c["initial"]["actuated_deg"] = {0.0};
  CHECK_THROWS_WITH_AS(buildLab(*findLab("fivebar"), c, file),
                       (file + ": /actuated: expected one actuated joint per degree of freedom for a task path: the model "
                               "file's mechanism has 2 after its loops close, 1 actuated (`dynlab model FILE` shows its "
                               "joints and loops)").c_str(),
                       InputError);
}
