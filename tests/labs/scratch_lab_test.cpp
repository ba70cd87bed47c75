// The lab contract is checkable on a lab the repository does not have: a pendulum defined here,
// registered at run time (registerLab), goes through the same checks as every registered lab
// (lab_checks.h checkLab, without the CLI: the dynlab binary does not know it).
//   m l² θ'' = −m g l sin θ + τ,   τ = k_p (θ_d − θ) − k_d θ'   (law "pd"; "p": k_d unused)
#include <doctest/doctest.h>

#include <cmath>

#include "tests/labs/lab_checks.h"

using namespace dyn;

namespace {

struct Pendulum {
  double m = 1, l = 0.5, g = 9.81, theta0 = 0.2, theta_d = 0.3, kp = 20, kd = 2;
  bool control = true, derivative = true;
  SimulationSettings sim;
};

// Hand: RK4; the stand-in reference: semi-implicit Euler (first order, as a reference engine).
class PendulumRun final : public Simulation {
 public:
  PendulumRun(const Pendulum& p, bool rk4) : p_(p), rk4_(rk4), th_(p.theta0) {}
  bool step(std::vector<double>& row) override {
    if (k_ >= std::lround(p_.sim.duration / p_.sim.step.dt)) return false;
    const double dt = p_.sim.step.dt, tau = torque();
    row = {double(k_) * dt, th_, w_, tau, energy()};
    auto acc = [&](double th) { return (-p_.m * p_.g * p_.l * std::sin(th) + tau) / (p_.m * p_.l * p_.l); };
    if (rk4_) {
      // τ held over the step (zero-order hold), as every engine does.
      const double k1 = w_, a1 = acc(th_), k2 = w_ + 0.5 * dt * a1, a2 = acc(th_ + 0.5 * dt * k1);
      const double k3 = w_ + 0.5 * dt * a2, a3 = acc(th_ + 0.5 * dt * k2), k4 = w_ + dt * a3, a4 = acc(th_ + dt * k3);
      th_ += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      w_ += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    } else {
      w_ += dt * acc(th_);
      th_ += dt * w_;
    }
    ++k_;
    return true;
  }

 private:
  double torque() const { return p_.control ? p_.kp * (p_.theta_d - th_) - (p_.derivative ? p_.kd * w_ : 0.0) : 0.0; }
  double energy() const { return 0.5 * p_.m * p_.l * p_.l * w_ * w_ + p_.m * p_.g * p_.l * (1 - std::cos(th_)); }
  Pendulum p_;
  bool rk4_;
  double th_, w_ = 0;
  long k_ = 0;
};

class PendulumLab final : public Lab {
 public:
  explicit PendulumLab(Pendulum p) : p_(p) {}
  std::vector<std::string> columns() const override { return {"t", "theta", "omega", "tau", "energy"}; }
  double dt() const override { return p_.sim.step.dt; }
  double duration() const override { return p_.sim.duration; }
  std::unique_ptr<Simulation> simulate(Engine e) const override { return std::make_unique<PendulumRun>(p_, e == Engine::Hand); }
  json metrics(const Trace& tr) const override {
    double s = 0, tau = 0;
    for (std::size_t r = 0; r < tr.rows(); ++r) {
      s += std::pow(tr.at(r, "theta") - p_.theta_d, 2);
      tau = std::max(tau, std::abs(tr.at(r, "tau")));
    }
    return {{"theta_rms", tr.rows() ? std::sqrt(s / double(tr.rows())) : 0.0}, {"tau_max", tau}};
  }
  json agreement(const Trace& a, const Trace& b) const override {
    double d = 0;
    for (std::size_t r = 0; r < std::min(a.rows(), b.rows()); ++r) d = std::max(d, std::abs(a.at(r, "theta") - b.at(r, "theta")));
    return {{"max_dtheta", d}};
  }
  std::string agreementUnit(const std::string& key) const override { return key == "max_dtheta" ? "rad" : ""; }
  PassiveEnergy passiveEnergy() const override { return {1e-8, 1.0}; }
  void scene(const Trace& tr, std::size_t row, const Trace*, Scene& out) const override {
    const double th = tr.at(row, "theta");
    const Eigen::Vector3d bob(p_.l * std::sin(th), -p_.l * std::cos(th), 0);
    out.capsules.push_back({Eigen::Vector3d::Zero(), bob, 0.02, {0.2f, 0.3f, 0.8f, 1.0f}});
    out.spheres.push_back({bob, 0.06, {0.8f, 0.2f, 0.2f, 1.0f}});
    out.camera.half_height = 0.7;
  }
  void overlay(const Trace& tr, std::size_t row, Overlay& out) const override {
    out.title = "pendulum";
    out.lines.push_back({"theta", std::to_string(tr.at(row, "theta")) + " rad"});
  }
  std::vector<LinearLoop> linearise() const override {
    // About θ = 0: m l² s² + m g l, feedback k_d s + k_p (nothing when the controller is off).
    const double kp = p_.control ? p_.kp : 0, kd = p_.control && p_.derivative ? p_.kd : 0;
    return {{"angle", "pendulum angle loop", {kp, kd}, {p_.m * p_.g * p_.l, 0, p_.m * p_.l * p_.l}, 0.5 * p_.sim.step.dt}};
  }

 private:
  Pendulum p_;
};

std::unique_ptr<Lab> buildPendulum(const JsonView& c) {
  c.onlyKeys({"lab", "simulation", "controller", "gains", "submission_options", "rubric"});
  Pendulum p;
  p.sim = parseSimulation(c["simulation"]);
  c["controller"].onlyKeys({"kind", "law", "seed"});
  p.control = c["controller"]["kind"].oneOf({"none", "pd"}) == "pd";
  p.derivative = c["controller"]["law"].oneOf({"pd", "p"}) == "pd";
  const auto g = parseGains(c["gains"], {"kp", "kd"});
  p.kp = g.at("kp");
  p.kd = g.at("kd");
  return std::make_unique<PendulumLab>(p);
}

const json kConfig = json::parse(R"json({
  "lab": "scratch_pendulum",
  "simulation": {"dt": 0.001, "duration": 2.0, "integrator": "rk4", "drift": "none"},
  "controller": {"kind": "pd", "law": "pd", "seed": 1},
  "gains": {"kp": {"value": 20, "min": 0, "max": 200, "unit": "N·m/rad", "doc": "stiffness"},
            "kd": {"value": 2, "min": 0, "max": 20, "unit": "N·m·s/rad", "doc": "damping"}},
  "submission_options": {"law": {"target": "/controller/law", "choices": ["pd", "p"], "doc": "the control law"}},
  "rubric": {
    "seed_target": "/controller/seed",
    "scenarios": {"nominal": {"about": "as given"}},
    "watchdog": {"max_steps": 10000, "limits": [{"column": "theta", "min": -10, "max": 10, "what": "the angle"}]},
    "tests": [
      {"name": "Angle reaches θ_d", "metric": "theta_rms", "full": 0.05, "zero": 0.2, "points": 2,
       "plot": {"columns": ["theta"], "band": 0.05, "ylabel": "theta (rad)"}},
      {"name": "Angle loop damping", "metric": "angle_damping", "full": 0.7, "zero": 0.1, "points": 1}
    ]
  }
})json");

}  // namespace

TEST_CASE("a scratch lab registered at run time passes the lab contract checks, and is removed again") {
  REQUIRE(registerLab({"scratch_pendulum", "a pendulum defined in a test", buildPendulum}));
  CHECK_FALSE(registerLab({"scratch_pendulum", "the same name again", buildPendulum}));  // a name is taken once
  const test::cli::TempDir dir("scratch_lab_examples");
  test::cli::writeFile(dir / "pd.json", R"({"lab": "scratch_pendulum", "gains": {"kp": 40, "kd": 4}})");
  test::cli::writeFile(dir / "p.json", R"({"lab": "scratch_pendulum", "law": "p", "gains": {"kp": 40, "kd": 0}})");
  test::checkLab(*findLab("scratch_pendulum"), kConfig, {dir.path.string(), false});
  CHECK(unregisterLab("scratch_pendulum"));
  CHECK(findLab("scratch_pendulum") == nullptr);
  CHECK_FALSE(unregisterLab("scratch_pendulum"));
}
