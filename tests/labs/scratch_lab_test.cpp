// A lab made in a test: a double pendulum under joint PD control, described in a few lines, run by both
// engines through the shared harness (labs/mechanism_simulation.h), registered for this test only and
// put through every check of the lab contract (tests/labs/lab_checks.h) — with no file outside this
// test. What a new lab folder needs, and nothing more.
#include <doctest/doctest.h>

#include <cmath>

#include "labs/mechanism_simulation.h"
#include "labs/settings.h"
#include "physics/constrained_mechanism.h"
#include "tests/labs/lab_checks.h"

using namespace dyn;

namespace {

const char* kConfig = R"({
  "lab": "scratch_pendulum",
  "mechanism": {"lengths": [0.4, 0.3], "masses": [1.0, 0.5]},
  "initial": {"q": [1.0, -0.5]},
  "simulation": {"dt": 0.001, "duration": 1.0, "integrator": "rk4", "drift": "projection"},
  "controller": {"kind": "pd", "target": [0.3, 0.0]},
  "gains": {"kp": {"value": 16, "min": 0, "max": 1000, "unit": "N·m/rad", "doc": "joint stiffness"},
            "kd": {"value": 2, "min": 0, "max": 100, "unit": "N·m·s/rad", "doc": "joint damping"}},
  "rubric": {"scenarios": {"nominal": {"about": "as given"},
                           "heavy": {"about": "second link 1 kg", "patch": {"mechanism": {"masses": [1.0, 1.0]}}}},
             "watchdog": {"max_steps": 10000, "limits": [{"column": "q1", "min": -50, "max": 50, "what": "the first angle"}]},
             "tests": [{"name": "Settles at the target", "scenario": "nominal", "metric": "e_final", "full": 0.05, "zero": 0.5, "points": 2},
                       {"name": "Settles with a heavier link", "scenario": "heavy", "metric": "e_final", "full": 0.05, "zero": 0.5, "points": 1}],
             "lessons": [{"about": "a stiff, damped PD settles where a soft one sags", "better": "good.json", "worse": "soft.json", "margin": 0.3}]}
})";

const std::vector<std::string> kColumns = {"t", "q1", "q2", "tau1", "tau2", "energy", "constraint_residual", "work"};

struct Settings {
  MechanismModel<Planar> model;
  VecN q0 = VecN::Zero(2);
  SimulationSettings sim;
  bool pd = true;
  double kp = 0, kd = 0;
  Eigen::Vector2d target = Eigen::Vector2d::Zero();
};

// The mechanism: two links hanging from the world, each a rod of its length and mass.
Settings parse(const JsonView& c) {
  Settings s;
  const JsonView m = c["mechanism"];
  for (int i = 0; i < 2; ++i) {
    const double l = m["lengths"].at(std::size_t(i)).positive(10), mass = m["masses"].at(std::size_t(i)).positive(100);
    const Planar::Pos joint = i == 0 ? Planar::Pos::Zero() : Planar::Pos(m["lengths"].at(0).positive(10), 0.0);
    s.model.tree.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(joint),
                         Planar::inertia(mass, Planar::Pos(l / 2, 0), mass * l * l / 12));
  }
  s.model.tree.gravity << 0, 0, -9.81;
  for (int i = 0; i < 2; ++i) s.q0[i] = c["initial"]["q"].at(std::size_t(i)).inRange(-10, 10);
  s.sim = parseSimulation(c["simulation"]);
  s.pd = c["controller"]["kind"].oneOf({"none", "pd"}) == "pd";
  if (c["controller"].has("target"))
    for (int i = 0; i < 2; ++i) s.target[i] = c["controller"]["target"].at(std::size_t(i)).inRange(-10, 10);
  const auto g = parseGains(c["gains"], {"kp", "kd"});
  s.kp = g.at("kp"), s.kd = g.at("kd");
  return s;
}

// The lab's part of a step: τ = kp (θ_d − θ) − kd θ', and its row.
class Hooks final : public StepHooks {
 public:
  explicit Hooks(const Settings& s) : s_(s) {}
  VecN torque(double, const VecN& q, const VecN& v) override {
    if (!s_.pd) return VecN::Zero(2);
    return VecN(s_.kp * (VecN(s_.target) - q) - s_.kd * v);
  }
  void row(const StepRecord& r, std::vector<double>& out) override {
    out = {r.t, r.q[0], r.q[1], r.tau[0], r.tau[1], r.energy, r.residual, r.work};
  }

 private:
  const Settings& s_;
};

class PendulumLab final : public Lab {
 public:
  explicit PendulumLab(const JsonView& c) : s_(parse(c)) {}
  std::vector<std::string> columns() const override { return kColumns; }
  double dt() const override { return s_.sim.step.dt; }
  double duration() const override { return s_.sim.duration; }
  std::unique_ptr<Simulation> simulate(Engine engine) const override {
    using Mech = ConstrainedMechanism<Planar>;
    auto mech = std::make_unique<Mech>(s_.model);
    std::unique_ptr<MechanismEngine> stepper;
    if (engine == Engine::Hand) stepper = std::make_unique<HandEngine<Mech>>(*mech, s_.sim.step, s_.q0, VecN::Zero(2));
    else stepper = std::make_unique<BulletEngine<Planar>>(s_.model, dt(), s_.q0, VecN::Zero(2));
    return std::make_unique<MechanismSimulation<Mech>>(engine, std::move(mech), std::move(stepper),
                                                       std::make_unique<Hooks>(s_), kColumns, dt(), duration());
  }
  json metrics(const Trace& tr) const override {
    const std::size_t last = tr.rows() ? tr.rows() - 1 : 0;
    const double e = tr.rows() ? std::hypot(tr.at(last, "q1") - s_.target[0], tr.at(last, "q2") - s_.target[1]) : 0.0;
    double drift = 0;
    for (std::size_t r = 0; r < tr.rows(); ++r) drift = std::max(drift, std::abs(tr.at(r, "energy") - tr.at(0, "energy") - tr.at(r, "work")));
    return {{"e_final", e}, {"energy_drift", drift}};
  }
  json agreement(const Trace& a, const Trace& b) const override {
    double dq = 0;
    for (std::size_t r = 0; r < std::min(a.rows(), b.rows()); ++r)
      dq = std::max({dq, std::abs(a.at(r, "q1") - b.at(r, "q1")), std::abs(a.at(r, "q2") - b.at(r, "q2"))});
    return {{"max_dq", dq}};
  }
  void scene(const Trace& tr, std::size_t row, const Trace*, Scene& out) const override {
    const double a1 = tr.at(row, "q1"), a2 = a1 + tr.at(row, "q2");
    const Eigen::Vector3d p1(0.4 * std::cos(a1), 0.4 * std::sin(a1), 0), p2 = p1 + Eigen::Vector3d(0.3 * std::cos(a2), 0.3 * std::sin(a2), 0);
    out.capsules.push_back({Eigen::Vector3d::Zero(), p1, 0.02, {0.2f, 0.4f, 0.7f, 1}});
    out.capsules.push_back({p1, p2, 0.02, {0.2f, 0.4f, 0.7f, 1}});
    out.camera.half_height = 0.8;
  }
  void overlay(const Trace& tr, std::size_t row, Overlay& out) const override {
    out.title = "scratch pendulum";
    out.lines = {{"t", std::to_string(tr.at(row, "t"))}};
  }
  PassiveEnergy passiveEnergy() const override { return {1e-7, 1.0}; }

 private:
  Settings s_;
};

}  // namespace

TEST_CASE("a lab described in a test file keeps the whole lab contract, on both engines") {
  const LabFactory make = [](const JsonView& c) -> std::unique_ptr<Lab> { return std::make_unique<PendulumLab>(c); };
  REQUIRE(registerLab({"scratch_pendulum", "A double pendulum made in a test", make}));
  CHECK_FALSE(registerLab({"scratch_pendulum", "the same name again", make}));  // a name is taken once
  const test::cli::TempDir dir("scratch_lab_examples");
  test::cli::writeFile(dir / "good.json", R"({"lab": "scratch_pendulum", "gains": {"kp": 60, "kd": 6}})");
  test::cli::writeFile(dir / "soft.json", R"({"lab": "scratch_pendulum", "gains": {"kp": 16, "kd": 2}})");
  test::LabCheckOptions options;
  options.examples_dir = dir.path.string();
  options.lab_dir = dir.path.string();  // the lesson's pair
  options.instructor_dir = "-";
  options.cli = false;  // the dynlab binary does not know a lab made here
  test::checkLab(*findLab("scratch_pendulum"), json::parse(kConfig), options);
  // Both engines really ran the same pendulum: Bullet's first-order step stays close to RK4 over 1 s.
  const auto lab = buildLab(*findLab("scratch_pendulum"), json::parse(kConfig), "scratch.json");
  const RunResult hand = runEngine(*lab, Engine::Hand), bullet = runEngine(*lab, Engine::Bullet);
  const double dq = lab->agreement(hand.trace, bullet.trace)["max_dq"].get<double>();
  MESSAGE("scratch pendulum, hand vs Bullet over 1 s at dt = 1 ms: max |Δq| = ", dq, " rad");
  CHECK(dq > 0);
  CHECK(dq < 1e-2);
  CHECK(unregisterLab("scratch_pendulum"));
  CHECK(findLab("scratch_pendulum") == nullptr);
}
