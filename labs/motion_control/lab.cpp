// Motion-control lab: parses motion_control.json, runs the arm on the hand-written model (fixed sizes
// for 3 links) or on Bullet with the same controller, and measures the runs.
#include "labs/motion_control/lab.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "labs/settings.h"

namespace dyn::motion_control {
namespace {

constexpr double kMaxLength = 100, kMaxMass = 1e6, kMaxGravity = 1e3, kMaxTorque = 1e5;
constexpr int kMaxLinks = 8;  // flexible: 2 tree joints per link, within kMaxDof

std::string col(const char* base, int i) { return base + std::to_string(i + 1); }

Link parseLink(const JsonView& j) {
  j.onlyKeys({"length", "mass", "inertia", "com"});
  j["com"].size(2, 2);
  return {j["length"].positive(kMaxLength), j["mass"].positive(kMaxMass), j["inertia"].positive(kMaxMass),
          {j["com"].at(0).inRange(-kMaxLength, kMaxLength), j["com"].at(1).inRange(-kMaxLength, kMaxLength)}};
}

// An array of exactly n numbers in [lo, hi].
Eigen::VectorXd parseArray(const JsonView& j, int n, double lo, double hi, double scale = 1.0) {
  j.size(std::size_t(n), std::size_t(n));
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x[i] = j.at(std::size_t(i)).inRange(lo, hi) * scale;
  return x;
}

std::vector<JointFriction> parseFriction(const JsonView& j, int n) {
  j.size(std::size_t(n), std::size_t(n));
  std::vector<JointFriction> f;
  for (int i = 0; i < n; ++i) {
    const JsonView e = j.at(std::size_t(i));
    e.onlyKeys({"viscous", "coulomb"});
    f.push_back({e["viscous"].inRange(0, kMaxTorque), e["coulomb"].inRange(0, kMaxTorque)});
  }
  return f;
}

// The lab's part of a run: the controller held over its period, the trace row.
class Hooks final : public StepHooks {
 public:
  explicit Hooks(const Settings& s)
      : s_(s), ctrl_(s.controller, s.trajectory, s.model),
        hold_(std::max(1L, std::lround(s.controller.period / s.step.dt))) {}
  VecN torque(double t, const VecN& q, const VecN& v) override {
    const ArmState a = armState(s_.plant, q, v);
    if (k_++ % hold_ == 0) tau_ = ctrl_.torque(t, a.motor, a.motor_rate), sat_ = ctrl_.saturated();
    return treeTorque(s_.plant, tau_);
  }
  void row(const StepRecord& r, std::vector<double>& out) override {
    const int n = s_.plant.n();
    const ArmState a = armState(s_.plant, r.q, r.v);
    Eigen::VectorXd qd, qdd_rate, qdd;
    s_.trajectory.at(r.t, qd, qdd_rate, qdd);
    const Eigen::VectorXd e = a.link - qd;
    out.clear();
    out.push_back(r.t);
    for (int i = 0; i < n; ++i) out.push_back(a.link[i]);
    for (int i = 0; i < n; ++i) out.push_back(qd[i]);
    for (int i = 0; i < n; ++i) out.push_back(e[i]);
    for (int i = 0; i < n; ++i) out.push_back(tau_[i]);
    out.push_back(sat_ ? 1.0 : 0.0);
    out.push_back(r.energy);
    out.push_back(r.work);
    // V on the controller's side (motor angles, the model's M̂), for pd_gravity's check.
    out.push_back(ctrl_.lyapunov(a.motor - qd, a.motor, a.motor_rate));
    for (int i = 0; i < n; ++i) out.push_back(a.deflection[i]);
    for (int i = 0; i < n; ++i) out.push_back(ctrl_.integral()[i]);
  }

 private:
  const Settings& s_;
  Controller ctrl_;
  long hold_, k_ = 0;
  Eigen::VectorXd tau_;
  bool sat_ = false;
};

template <class M>
std::unique_ptr<Simulation> run(const Settings& s, Engine engine, const std::vector<std::string>& columns) {
  auto mech = std::make_unique<M>(describe(s.plant));
  VecN q, v;
  treeState(s.plant, s.trajectory.outstretched, staticDeflection(s.plant, s.trajectory.outstretched), q, v);
  return simulateMechanism(engine, std::move(mech), s.step, q, v, std::make_unique<Hooks>(s), columns, s.duration);
}

}  // namespace

Eigen::VectorXd staticDeflection(const Params& p, const Eigen::VectorXd& theta) {
  const int n = p.n();
  Eigen::VectorXd d = Eigen::VectorXd::Zero(n);
  if (!p.flexible) return d;
  ArmMechanism mech(describe(p));
  // Fixed point: the springs carry the gravity torque across each joint at the deflected pose
  // (G of the spring joints, springs excluded: k_i δ_i + G_i = 0).
  for (int it = 0; it < 200; ++it) {
    VecN q, v;
    treeState(p, theta, d, q, v);
    const VecN G = mech.gravityTorque(q);
    Eigen::VectorXd next(n);
    for (int i = 0; i < n; ++i) next[i] = -G[2 * i + 1] / p.stiffness[std::size_t(i)];
    const double change = (next - d).cwiseAbs().maxCoeff();
    d = next;
    if (change < 1e-14) break;
  }
  return d;
}

double fastestMode(const Params& p, const Eigen::VectorXd& theta) {
  if (!p.flexible) return 0.0;
  const int n = p.n();
  ArmMechanism mech(describe(p));
  VecN q, v;
  treeState(p, theta, Eigen::VectorXd::Zero(n), q, v);
  const Eigen::MatrixXd M = mech.massMatrix(q);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  for (int i = 0; i < n; ++i) K(2 * i + 1, 2 * i + 1) = p.stiffness[std::size_t(i)];
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(0.0, eig.eigenvalues().maxCoeff()));
}

Settings parseSettings(const JsonView& c) {
  Settings s;
  c.onlyKeys({"lab", "title", "description", "variants", "mechanism", "model", "trajectory", "simulation", "controller", "gains",
              "metrics", "rubric", "drawing", "submission_options", "metric_docs", "map", "figures"});
  const JsonView m = c["mechanism"];
  m.onlyKeys({"links", "friction", "coulomb_width", "payload", "gravity", "torque_limit", "flexible"});
  const int n = int(m["links"].size(1, kMaxLinks));
  for (int i = 0; i < n; ++i) s.plant.links.push_back(parseLink(m["links"].at(std::size_t(i))));
  s.plant.friction = parseFriction(m["friction"], n);
  s.plant.coulomb_width = m["coulomb_width"].positive(1e3);
  s.plant.payload = m["payload"].inRange(0, kMaxMass);
  m["gravity"].size(2, 2);
  s.plant.gravity = {m["gravity"].at(0).inRange(-kMaxGravity, kMaxGravity), m["gravity"].at(1).inRange(-kMaxGravity, kMaxGravity)};
  s.plant.stiffness.assign(std::size_t(n), 0.0);
  if (m.has("flexible")) {
    const JsonView f = m["flexible"];
    f.onlyKeys({"enabled", "stiffness", "rotor_inertia", "rotor_mass"});
    s.plant.flexible = f["enabled"].boolean();
    const Eigen::VectorXd k = parseArray(f["stiffness"], n, 1e-3, 1e9);
    s.plant.stiffness.assign(k.data(), k.data() + n);
    s.plant.rotor_inertia = f["rotor_inertia"].positive(kMaxMass);
    s.plant.rotor_mass = f["rotor_mass"].positive(kMaxMass);
  }
  // The model: the same links, its own payload and friction estimate; always rigid.
  const JsonView md = c["model"];
  md.onlyKeys({"payload", "friction"});
  s.model = s.plant;
  s.model.flexible = false;
  s.model.payload = md["payload"].inRange(0, kMaxMass);
  s.model.friction = parseFriction(md["friction"], n);

  const JsonView tr = c["trajectory"];
  tr.onlyKeys({"outstretched_deg", "folded_deg", "move_time", "hold_time", "sine_amplitude_deg", "sine_period"});
  const double deg = M_PI / 180.0;
  auto& T = s.trajectory;
  T.outstretched = parseArray(tr["outstretched_deg"], n, -360, 360, deg);
  T.folded = parseArray(tr["folded_deg"], n, -360, 360, deg);
  T.amplitude = parseArray(tr["sine_amplitude_deg"], n, -360, 360, deg);
  T.move_time = tr["move_time"].inRange(1e-3, 1e4);
  T.hold_time = tr["hold_time"].inRange(0, 1e4);
  T.period = tr["sine_period"].inRange(1e-2, 1e4);

  const SimulationSettings sim = parseSimulation(c["simulation"]);
  s.step = sim.step;
  s.duration = sim.duration;
  // Coulomb friction where it turns: those RK4 steps in kFrictionSubsteps sub-steps (mechanism.h RefinedArm).
  // Flexible joints: the hand engine sub-steps dt so that the fastest rotor–spring mode has
  // ω dt/substeps ≤ kResolvedOmegaDt; ω² the largest eigenvalue of K x = ω² M(θ) x (fastestMode: the
  // springs' stiffness against the whole mass matrix, the rotors' inertia in it) at the trajectory's two
  // poses (the outstretched one is the fastest pose of the arm: tests/labs/stiff_terms_test.cpp); the
  // trace keeps one row per dt.
  s.step.refine_substeps = kFrictionSubsteps;
  if (s.plant.flexible) {
    const double w = std::max(fastestMode(s.plant, T.outstretched), fastestMode(s.plant, T.folded));
    s.step.substeps = std::max(1, int(std::ceil(w * s.step.dt / kResolvedOmegaDt)));
  }

  const JsonView ctl = c["controller"];
  ctl.onlyKeys({"kind", "anti_windup", "control_period", "coulomb_compensation", "compensation_width", "tracking_time",
                "computed_torque_gains", "joint_scale", "constant_torque"});
  auto& cc = s.controller;
  const std::string kind = ctl["kind"].oneOf({"none", "constant", "pid", "computed_torque", "pd_gravity"});
  cc.kind = kind == "none" ? Kind::None : kind == "constant" ? Kind::Constant : kind == "pid" ? Kind::Pid
            : kind == "computed_torque" ? Kind::ComputedTorque : Kind::PdGravity;
  const std::string aw = ctl["anti_windup"].oneOf({"none", "clamping", "back_calculation"});
  cc.anti_windup = aw == "none" ? AntiWindup::None : aw == "clamping" ? AntiWindup::Clamping : AntiWindup::BackCalculation;
  cc.period = ctl["control_period"].inRange(s.step.dt, 1.0);
  const double ratio = cc.period / s.step.dt;
  if (std::abs(ratio - std::round(ratio)) > 1e-6)
    ctl["control_period"].fail("expected a whole multiple of the simulation step /simulation/dt");
  cc.coulomb_compensation = ctl["coulomb_compensation"].boolean();
  cc.compensation_width = ctl["compensation_width"].positive(1e3);
  cc.tracking_time = ctl["tracking_time"].positive(1e3);
  const bool ct_kp_kd = ctl["computed_torque_gains"].oneOf({"omega_zeta", "kp_kd"}) == "kp_kd";
  const Eigen::VectorXd scale = parseArray(ctl["joint_scale"], n, 0, 1e3);
  cc.constant = ctl.has("constant_torque") ? parseArray(ctl["constant_torque"], n, -kMaxTorque, kMaxTorque)
                                           : Eigen::VectorXd::Zero(n);
  cc.tau_max = parseArray(m["torque_limit"], n, 1e-6, kMaxTorque);

  // Gains: scalars, spread over the joints by joint_scale (pid, pd_gravity); computed torque's act on
  // the linearised error dynamics, the same for every joint.
  const auto g = parseGains(c["gains"], {"kp", "ki", "kd", "omega_n", "zeta"});
  if (cc.kind == Kind::ComputedTorque) {
    const double kp = ct_kp_kd ? g.at("kp") : g.at("omega_n") * g.at("omega_n");
    const double kd = ct_kp_kd ? g.at("kd") : 2 * g.at("zeta") * g.at("omega_n");
    cc.kp = Eigen::VectorXd::Constant(n, kp), cc.kd = Eigen::VectorXd::Constant(n, kd), cc.ki = Eigen::VectorXd::Zero(n);
  } else {
    cc.kp = g.at("kp") * scale, cc.ki = g.at("ki") * scale, cc.kd = g.at("kd") * scale;
  }
  return s;
}

MotionControlLab::MotionControlLab(Settings s) : SettingsLab(std::move(s)) {
  const int n = s_.plant.n();
  columns_ = {"t"};
  for (const char* base : {"q", "qd", "e", "tau"})
    for (int i = 0; i < n; ++i) columns_.push_back(col(base, i));
  for (const char* x : {"tau_sat", "energy", "work", "V"}) columns_.push_back(x);
  for (const char* base : {"defl", "u_i"})
    for (int i = 0; i < n; ++i) columns_.push_back(col(base, i));
  // The units of the arm's own columns; unit() adds the joints' (q*, qd*, e*, defl*, tau*, u_i*).
  units_ = {{"t", "s"}, {"energy", "J"}, {"work", "J"}, {"V", "J"}};
  agreement_units_ = {{"max_dq", "rad"}, {"max_dtau", "N·m"}};
  // Passive without friction (the conservative patch) the arm swings freely: RK4 keeps E within 1e-6·|E0|.
  json zero = json::array();
  for (int i = 0; i < n; ++i) zero.push_back({{"viscous", 0.0}, {"coulomb", 0.0}});
  passive_ = {1e-6, 1.0, {{"mechanism", {{"friction", zero}}}}};
}

std::string MotionControlLab::unit(const std::string& c) const {
  if (const auto u = SettingsLab::unit(c); !u.empty()) return u;
  for (const char* base : {"q", "qd", "e", "defl"})
    if (c.rfind(base, 0) == 0 && c.size() > std::string(base).size() && std::isdigit(c[std::string(base).size()])) return "rad";
  if (c.rfind("tau", 0) == 0 && c != "tau_sat") return "N·m";
  if (c.rfind("u_i", 0) == 0) return "N·m";
  return {};
}

std::unique_ptr<Simulation> MotionControlLab::simulate(Engine engine) const {
  const int n = s_.plant.n();
  const auto cols = columns();
  if (n == 3 && !s_.plant.flexible) return run<RefinedArm<FixedArm<3>>>(s_, engine, cols);
  if (n == 3 && s_.plant.flexible) return run<RefinedArm<FixedArm<6>>>(s_, engine, cols);
  return run<RefinedArm<ArmMechanism>>(s_, engine, cols);
}

MujocoTwin MotionControlLab::mujocoTwin() const {
  MujocoTwin t;
  if (s_.plant.flexible || s_.plant.n() != 3) return t;  // the file is the default rigid 3-link arm
  t.file = "mujoco.xml";
  t.stands_in = "Coulomb friction as MuJoCo's frictionloss rows (the lab's is smooth: F_c tanh(θ'/w))";
  treeState(s_.plant, s_.trajectory.outstretched, staticDeflection(s_.plant, s_.trajectory.outstretched), t.q, t.v);
  t.dynamics = handDynamics(describe(s_.plant));
  return t;
}

json MotionControlLab::metrics(const Trace& tr) const {
  const int n = s_.plant.n();
  const Trajectory& T = s_.trajectory;
  std::vector<double> all, folded, out;
  double e_final = 0, tau_peak = 0, tau_tv = 0, drift = 0, v_rise = 0, overshoot = 0, sat_time = 0, defl_max = 0;
  const double e0 = tr.rows() ? tr.at(0, "energy") : 0;
  const Eigen::VectorXd d = T.folded - T.outstretched;
  const auto t_col = tr.col("t"), tau_sat = tr.col("tau_sat"), energy = tr.col("energy"), work = tr.col("work"), V = tr.col("V");
  std::vector<Trace::Column> e_c, tau_c, defl_c, q_c;  // joint i's columns
  for (int i = 0; i < n; ++i)
    e_c.push_back(tr.col(col("e", i))), tau_c.push_back(tr.col(col("tau", i))), defl_c.push_back(tr.col(col("defl", i))),
        q_c.push_back(tr.col(col("q", i)));
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    const double t = t_col[r];
    double e2 = 0;
    for (int i = 0; i < n; ++i) {
      const double e = e_c[i][r];
      e2 += e * e;
      all.push_back(e);
      const double tau = tau_c[i][r];
      tau_peak = std::max(tau_peak, std::abs(tau));
      if (r > 0) tau_tv += std::abs(tau - tau_c[i][r - 1]);
      defl_max = std::max(defl_max, std::abs(defl_c[i][r]));
      // Overshoot past the folded target while holding there, as a share of the move.
      if (t >= T.t1() && t < T.t2() && std::abs(d[i]) > 1e-9)
        overshoot = std::max(overshoot, (d[i] > 0 ? 1 : -1) * (q_c[i][r] - T.folded[i]) / std::abs(d[i]));
    }
    if (t >= T.t1() && t < T.t2()) folded.push_back(std::sqrt(e2 / n));
    if (t >= T.t3() && t < T.t4()) out.push_back(std::sqrt(e2 / n));
    if (r + 1 == tr.rows()) e_final = std::sqrt(e2 / n);
    sat_time += tau_sat[r] * s_.step.dt;
    drift = std::max(drift, std::abs(energy[r] - e0 - work[r]));
    if (r > 0) v_rise = std::max(v_rise, V[r] - V[r - 1]);
  }
  return {{"e_rms", rms(all)},          {"e_final", e_final},     {"e_rms_folded", rms(folded)},
          {"e_rms_outstretched", rms(out)}, {"overshoot", std::max(0.0, overshoot)}, {"tau_peak", tau_peak},
          {"tau_variation", tau_tv},    {"saturated_time", sat_time}, {"energy_drift", drift},
          {"energy_initial", e0},       {"V_max_rise", v_rise},   {"max_deflection", defl_max},
          {"max_constraint_residual", 0.0}, {"steps", tr.steps()}};
}

json MotionControlLab::differences(const Trace& a, const Trace& b, std::size_t rows) const {
  double dq = 0, dtau = 0;
  for (std::size_t r = 0; r < rows; ++r)
    for (int i = 0; i < s_.plant.n(); ++i) {
      dq = std::max(dq, std::abs(a.at(r, col("q", i)) - b.at(r, col("q", i))));
      dtau = std::max(dtau, std::abs(a.at(r, col("tau", i)) - b.at(r, col("tau", i))));
    }
  return {{"max_dq", dq}, {"max_dtau", dtau}};
}

DYNLAB_REGISTER_LAB(motion_control, "Motion control: PID, computed torque and PD + gravity on an arm, rigid or with flexible joints",
                    labFactory<MotionControlLab>(parseSettings));

}  // namespace dyn::motion_control
