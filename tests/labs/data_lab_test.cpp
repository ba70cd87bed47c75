// The pieces of a lab without C++ (labs/generic, labs/controllers), against closed forms:
//  * the task path: continuous to the acceleration at every segment's ends, x' and x'' equal central
//    differences of x and x', a circle keeps its radius and one turn returns to its start;
//  * metrics as data: each statistic on a trace with known values;
//  * task-space inverse dynamics on the five-bar with the exact model: the tool's error follows the
//    closed form of e'' + 2ζω e' + ω² e = 0, the deviation first order in the control period (its hold);
//  * a data lab's JSON: every bad field a one-line error naming its JSON path.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "labs/controllers/controller.h"
#include "labs/generic/data_lab.h"
#include "labs/generic/metric_spec.h"
#include "labs/generic/task_path.h"
#include "physics/model_file/model_file.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

json fivebarConfig() { return loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar/fivebar.json"); }

VecN vec(std::initializer_list<double> x) {
  VecN v(Eigen::Index(x.size()));
  int i = 0;
  for (double e : x) v[i++] = e;
  return v;
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
  const auto m = generic::parseMetrics(JsonView(spec, "lab.json", "/metrics"), tr.columns);
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
  CHECK_THROWS_WITH_AS(generic::parseMetrics(JsonView(bad, "lab.json", "/metrics"), tr.columns), doctest::Contains("/metrics/e/of"), InputError);
  const json band = json::parse(R"({"e": {"of": "a", "stat": "rms", "band": 1}})");
  CHECK_THROWS_WITH_AS(generic::parseMetrics(JsonView(band, "lab.json", "/metrics"), tr.columns), doctest::Contains("/metrics/e/band"), InputError);
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
  struct Case {
    const char* patch;
    const char* path;
    const char* says;
  };
  const Case cases[] = {
      {R"({"model_file": "../fivebar.xml"})", "/model_file", "without \"..\""},
      {R"({"model_file": "/etc/passwd"})", "/model_file", "relative path"},
      {R"({"model_file": "broken.xml"})", "/model_file", "a model file dynlab reads"},
      {R"({"model_file": "missing.xml"})", "/model_file", "not found"},
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
  for (const Case& c : cases) {
    INFO(std::string(c.patch));
    const json config = mergePatch(fivebarConfig(), json::parse(c.patch));
    try {
      generic::parseDataSettings(JsonView(config, "fivebar.json"), "fivebar", dir.string());
      FAIL("accepted");
    } catch (const InputError& e) {
      const std::string what = e.what();
      CHECK(e.path() == c.path);
      CHECK(what.find(c.says) != std::string::npos);
      CHECK(what.find('\n') == std::string::npos);
    }
  }
  // The shipped config parses, with its columns.
  const auto s = generic::parseDataSettings(JsonView(fivebarConfig(), "fivebar.json"), "fivebar", dir.string());
  CHECK(s.columns.front() == "t");
  CHECK(std::find(s.columns.begin(), s.columns.end(), "f_pin_C_z") != s.columns.end());
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
