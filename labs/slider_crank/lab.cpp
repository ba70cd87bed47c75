// Slider-crank lab: parses slider_crank.json, runs the hand-written model (eq. 2 through the
// generic solve) or the Bullet reference with the same controller, and measures the runs.
#include "labs/slider_crank/lab.h"

#include <cmath>

#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "labs/settings.h"
#include "physics/det/det.h"

namespace dyn::slider_crank {
namespace {

// Physically sensible bounds on the config: beyond them the model is not a teaching lab any more
// and products such as m·g·l or k·x overflow to inf/NaN mid-run.
constexpr double kMaxLength = 100, kMaxMass = 1e6, kMaxGravity = 1e3, kMaxRate = 1e3;

const std::vector<std::string> kColumns = {
    "t",   "q1",   "q2",   "q3",     "x_c",    "v_c",    "f_Tx",                "f_Ty", "tau_T",
    "tau1", "tau2", "tau3", "energy", "constraint_residual", "x_d",  "f_des",  "f_meas", "work"};

Link parseLink(const JsonView& j) {
  j.onlyKeys({"length", "mass", "inertia", "com"});
  j["com"].size(2, 2);
  return {j["length"].positive(kMaxLength), j["mass"].positive(kMaxMass), j["inertia"].positive(kMaxMass),
          {j["com"].at(0).inRange(-kMaxLength, kMaxLength), j["com"].at(1).inRange(-kMaxLength, kMaxLength)}};
}

// Everything a run needs, and the one place the trace row is laid out.
struct RowState {
  double t;
  Eigen::Vector3d th, thd;
  double x_c, v_c;
  Eigen::Vector3d f_T, tau;
  double energy, residual, x_d, f_des, f_meas, work;
  void write(std::vector<double>& row) const {
    row = {t,      th[0],    th[1],    th[2],    x_c,    v_c,  f_T[1], f_T[2], f_T[0],
           tau[0], tau[1],   tau[2],   energy,   residual, x_d, f_des, f_meas, work};
  }
};

// The lab's part of a run on either engine (labs/mechanism_simulation.h): the force controller, the
// trace row, and the force sensor, which sees f_Ty of each step `delay` later. The controller's
// model is the arm without its tool; the sensor measures the arm as it is.
class Hooks final : public StepHooks {
 public:
  Hooks(const Settings& s, const VecN& q0, const VecN& v0) : s_(s), ctrl_(s.controller, s.reference, controllerModel(s.params), s.step.dt) {
    Mechanism plant(s.params);
    ctrl_.primeMeasurement(plant, q0, v0);
  }
  VecN torque(double t, const VecN& q, const VecN& v) override {
    return ctrl_.torque(t, q.head(3), v.head(3), q[3], v[3]);
  }
  void row(const StepRecord& r, std::vector<double>& out) override {
    RowState{r.t, r.q.head(3), r.v.head(3), r.q[3], r.v[3], r.forces[0].head(3), r.tau.head(3), r.energy, r.residual,
             ctrl_.reference().position(r.t), s_.controller.f_des, ctrl_.measured(), r.work}
        .write(out);
  }
  void observe(const StepRecord& r) override { ctrl_.measure(r.forces[0][2]); }

 private:
  const Settings& s_;
  Controller ctrl_;
};

}  // namespace

Params controllerModel(const Params& plant) {
  Params model = plant;
  model.tool_mass = 0.0;  // the tool is what the model does not know
  return model;
}

Settings parseSettings(const JsonView& c) {
  Settings s;
  c.onlyKeys({"lab", "title", "description", "variants", "mechanism", "initial", "simulation", "controller", "gains",
              "reference", "metrics", "rubric", "scenarios", "drawing", "submission_options",
              "metric_docs", "map"});
  const JsonView m = c["mechanism"];
  m.onlyKeys({"links", "load_mass", "tool_mass", "gravity"});
  m["links"].size(3, 3);
  for (int i = 0; i < 3; ++i) s.params.links[i] = parseLink(m["links"].at(i));
  s.params.load_mass = m["load_mass"].positive(kMaxMass);
  s.params.tool_mass = m.has("tool_mass") ? m["tool_mass"].inRange(0, kMaxMass) : 0.0;
  m["gravity"].size(2, 2);
  s.params.gravity = {m["gravity"].at(0).inRange(-kMaxGravity, kMaxGravity),
                      m["gravity"].at(1).inRange(-kMaxGravity, kMaxGravity)};

  const JsonView init = c["initial"];
  init.onlyKeys({"theta1_deg", "theta1_rate", "branch"});
  s.theta1 = init["theta1_deg"].inRange(-360, 360) * M_PI / 180.0;
  s.theta1_rate = init.has("theta1_rate") ? init["theta1_rate"].inRange(-kMaxRate, kMaxRate) : 0.0;
  if (init.has("branch")) s.branch = init["branch"].oneOf({"cos_positive", "cos_negative"}) == "cos_positive" ? 1 : -1;
  const auto& L = s.params.links;
  if (std::abs(L[0].length * det::sin(s.theta1)) > L[1].length)
    init["theta1_deg"].fail("expected a crank angle the rod can reach (|l1 sin θ1| ≤ l2)");

  const SimulationSettings sim = parseSimulation(c["simulation"], IndependentForm::Yes);  // recoverDependent from θ1
  s.step = sim.step;
  s.duration = sim.duration;

  const JsonView ctl = c["controller"];
  ctl.onlyKeys({"kind", "force_law", "force_setpoint", "delay", "noise_std", "seed"});
  auto& cc = s.controller;
  cc.kind = ctl["kind"].oneOf({"none", "force_control"}) == "none" ? ControllerKind::None : ControllerKind::ForceControl;
  const std::string law = ctl["force_law"].oneOf({"open_loop", "proportional", "integral"});
  cc.law = law == "open_loop" ? ForceLaw::OpenLoop : law == "proportional" ? ForceLaw::Proportional : ForceLaw::Integral;
  cc.f_des = ctl["force_setpoint"].inRange(-1e4, 1e4);
  cc.delay = ctl["delay"].inRange(0, 1);
  cc.noise_std = ctl.has("noise_std") ? ctl["noise_std"].inRange(0, 1e4) : 0.0;
  cc.seed = ctl.has("seed") ? std::uint64_t(ctl["seed"].integer(0, 1LL << 53)) : 1;

  // Gains: declared with value and bounds (the submission schema comes from here).
  const auto g = parseGains(c["gains"], {"kp_x", "kd_x", "kp_f", "ki_f"});
  cc.gains = {g.at("kp_x"), g.at("kd_x"), g.at("kp_f"), g.at("ki_f")};

  const JsonView ref = c["reference"];
  ref.onlyKeys({"kind", "amplitude", "period"});
  ref["kind"].oneOf({"raised_cosine"});
  s.reference.amplitude = ref["amplitude"].inRange(-2, 2);
  s.reference.period = ref["period"].inRange(1e-3, 1e6);

  parseMetricsAndDrawing(c, s.settle_time, s.arrow_scale);
  // The reference starts where the slider starts.
  Mechanism mech(s.params);
  VecN q, v;
  if (!mech.initialState(s.theta1, s.theta1_rate, s.branch, q, v))
    init.fail("expected an initial state the mechanism can assemble");
  s.reference.x0 = q[3];
  return s;
}

SliderCrankLab::SliderCrankLab(Settings s) : SettingsLab(std::move(s)) {
  columns_ = kColumns;
  units_ = {
      {"t", "s"},       {"q1", "rad"},   {"q2", "rad"},   {"q3", "rad"},    {"x_c", "m"},
      {"v_c", "m/s"},   {"f_Tx", "N"},   {"f_Ty", "N"},   {"tau_T", "N·m"}, {"tau1", "N·m"},
      {"tau2", "N·m"},  {"tau3", "N·m"}, {"energy", "J"}, {"x_d", "m"},     {"f_des", "N"},
      {"f_meas", "N"},  {"work", "J"},
      {"constraint_residual", "m, rad"}};  // |φ|∞ over (θ1+θ2+θ3, x_T − x_c, y_T)
  agreement_units_ = {{"max_dq", "rad"}, {"max_dx_c", "m"}, {"max_df", "N"}, {"max_dtau_T", "N·m"}};
  // Passive (τ = 0) the arm falls through its whole range; RK4 + projection keeps E within 1e-6·|E0|.
  passive_ = {1e-6, 0};
}

std::unique_ptr<Simulation> SliderCrankLab::simulate(Engine engine) const {
  auto mech = std::make_unique<Mechanism>(s_.params);
  VecN q, v;
  mech->initialState(s_.theta1, s_.theta1_rate, s_.branch, q, v);
  return simulateMechanism(engine, std::move(mech), s_.step, q, v, std::make_unique<Hooks>(s_, q, v), kColumns, s_.duration);
}

MujocoTwin SliderCrankLab::mujocoTwin() const {
  MujocoTwin t;
  t.file = "mujoco.xml";
  Mechanism(s_.params).initialState(s_.theta1, s_.theta1_rate, s_.branch, t.q, t.v);
  t.dynamics = handDynamics(describe(s_.params));
  return t;
}

json SliderCrankLab::metrics(const Trace& tr) const {
  std::vector<double> ex, ef;
  double ex_max = 0, ef_max = 0, tau_max = 0, drift = 0, residual = 0;
  const auto t = tr.col("t"), x_c = tr.col("x_c"), x_d = tr.col("x_d"), f_Ty = tr.col("f_Ty"), f_des = tr.col("f_des");
  const auto energy = tr.col("energy"), work = tr.col("work"), residual_col = tr.col("constraint_residual");
  const Trace::Column taus[] = {tr.col("tau1"), tr.col("tau2"), tr.col("tau3")};
  const double e0 = tr.rows() ? energy[0] : 0;
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    const double e = x_c[r] - x_d[r];
    ex.push_back(e);
    ex_max = std::max(ex_max, std::abs(e));
    if (t[r] >= s_.settle_time) {
      const double f = f_Ty[r] - f_des[r];
      ef.push_back(f);
      ef_max = std::max(ef_max, std::abs(f));
    }
    for (const auto& tau : taus) tau_max = std::max(tau_max, std::abs(tau[r]));
    // Energy balance: E − E0 − ∫ τ·θ' dt (zero for exact dynamics, with or without control).
    drift = std::max(drift, std::abs(energy[r] - e0 - work[r]));
    residual = std::max(residual, residual_col[r]);
  }
  return {{"x_rms", rms(ex)},          {"x_max_error", ex_max},
          {"f_rms", rms(ef)},          {"f_max_error", ef_max},
          {"tau_max", tau_max},        {"energy_drift", drift},
          {"energy_initial", e0},      {"max_constraint_residual", residual},
          {"steps", tr.steps()},        {"settle_time", s_.settle_time}};
}

json SliderCrankLab::differences(const Trace& a, const Trace& b, std::size_t n) const {
  double dq = 0, dx = 0, df = 0, dtau_T = 0;
  for (std::size_t r = 0; r < n; ++r) {
    for (const char* c : {"q1", "q2", "q3"}) dq = std::max(dq, std::abs(a.at(r, c) - b.at(r, c)));
    dx = std::max(dx, std::abs(a.at(r, "x_c") - b.at(r, "x_c")));
    for (const char* c : {"f_Tx", "f_Ty"}) df = std::max(df, std::abs(a.at(r, c) - b.at(r, c)));
    dtau_T = std::max(dtau_T, std::abs(a.at(r, "tau_T") - b.at(r, "tau_T")));
  }
  return {{"max_dq", dq}, {"max_dx_c", dx}, {"max_df", df}, {"max_dtau_T", dtau_T}};
}

DYNLAB_REGISTER_LAB(slider_crank, "Slider crank: move the slider along x_d(t) while regulating its rail force (direct force control on a closed chain)",
                    labFactory<SliderCrankLab>(parseSettings));

}  // namespace dyn::slider_crank
