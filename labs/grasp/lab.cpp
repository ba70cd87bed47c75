// Grasp lab: parses grasp.json, runs the hand-written model (eq. 3 through the generic solve) or the
// Bullet reference with the same controller, watches the friction cones, and measures the runs.
#include "labs/grasp/lab.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>

#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "labs/settings.h"
#include "physics/constraints/point_contact.h"
#include "physics/det/det.h"
#include "physics/forces.h"

namespace dyn::grasp {
namespace {

// Physically sensible bounds: beyond them the model is not a teaching lab any more.
constexpr double kMaxLength = 10, kMaxMass = 1e4, kMaxGravity = 1e3, kMaxForce = 1e4;

Eigen::Vector2d vec2(const JsonView& j, double lo, double hi) {
  j.size(2, 2);
  return {j.at(0).inRange(lo, hi), j.at(1).inRange(lo, hi)};
}

Finger parseFinger(const JsonView& j) {
  j.onlyKeys({"base", "links", "elbow", "contact", "normal"});
  Finger f;
  f.base = vec2(j["base"], -kMaxLength, kMaxLength);
  const JsonView links = j["links"];
  if (links.size() != 2) links.fail("expected the two links of a planar finger (a point contact leaves each finger two joints)");
  for (std::size_t i = 0; i < 2; ++i) {
    const JsonView l = links.at(i);
    l.onlyKeys({"length", "mass", "inertia"});
    Link link{l["length"].positive(kMaxLength), l["mass"].positive(kMaxMass), 0};
    link.inertia = l.has("inertia") ? l["inertia"].positive(kMaxMass) : link.mass * link.length * link.length / 12.0;
    f.links.push_back(link);
  }
  f.elbow = j["elbow"].oneOf({"positive", "negative"}) == "positive" ? 1 : -1;
  f.contact = vec2(j["contact"], -kMaxLength, kMaxLength);
  f.normal = vec2(j["normal"], -1e3, 1e3);
  if (f.normal.norm() < 1e-9) j["normal"].fail("expected a non-zero outward normal");
  return f;
}

// The one place the trace row is laid out; columns() follows it.
std::vector<std::string> makeColumns(int m) {
  std::vector<std::string> c = {"t"};
  for (int j = 1; j <= 2 * m; ++j) c.push_back("q" + std::to_string(j));
  for (int j = 1; j <= 2 * m; ++j) c.push_back("tau" + std::to_string(j));
  for (const char* s : {"x_o", "y_o", "psi_o", "vx_o", "vy_o", "w_o", "x_d", "y_d", "psi_d"}) c.push_back(s);
  for (int i = 1; i <= m; ++i)
    for (const char* s : {"_x", "_y"}) c.push_back("f" + std::to_string(i) + s);
  for (int i = 1; i <= m; ++i)
    for (const char* s : {"_n", "_t"}) c.push_back("f" + std::to_string(i) + s);
  for (const char* s : {"cone_margin", "f_int", "f_int_d", "f_int_meas", "squeeze", "energy", "work", "constraint_residual"}) c.push_back(s);
  return c;
}

// The lab's part of a run on either engine (labs/mechanism_simulation.h): the controller, the push,
// the trace row, the contact-force sensor and the slip watchdog.
class Hooks final : public StepHooks {
 public:
  Hooks(const Settings& s, const VecN& q0, const VecN& v0)
      : s_(s), ctrl_(s.controller, s.reference, s.model, s.step.dt), model_(s.params) {
    ctrl_.primeMeasurement(model_, q0, v0);
  }
  // The controller's τ (the push is the mechanism's external force: simulate()).
  VecN torque(double t, const VecN& q, const VecN& v) override { return ctrl_.torque(t, q, v); }
  void row(const StepRecord& r, std::vector<double>& out) override {
    const int m = model_.fingers(), n = 2 * m;
    Eigen::Vector3d pose_d, rate_d, accel_d;
    ctrl_.reference().at(r.t, pose_d, rate_d, accel_d);
    out.assign(1, r.t);
    for (int j = 0; j < n; ++j) out.push_back(r.q[j]);
    for (int j = 0; j < n; ++j) out.push_back(r.tau[j]);
    for (const double x : {r.q[n + 1], r.q[n + 2], r.q[n], r.v[n + 1], r.v[n + 2], r.v[n], pose_d[1], pose_d[2], pose_d[0]})
      out.push_back(x);
    contactForces(r, F_);
    for (int j = 0; j < n; ++j) out.push_back(F_[j]);
    margin_ = INFINITY;
    for (int i = 0; i < m; ++i) {
      double c[3];  // f_n, f_t, margin: the point contact's own definitions
      PointContact<Planar>::contactAxes(F_.segment<2>(2 * i), model_.contactNormal(i, r.q[n]), s_.params.mu, c);
      out.push_back(c[0]);
      out.push_back(c[1]);
      if (c[2] < margin_) margin_ = c[2], worst_ = i, worst_fn_ = c[0], worst_ft_ = c[1];
    }
    // f_int_d: the set point the squeeze law would aim at with a perfect, undelayed sensor.
    const double f_int_d = ctrl_.setPointFor(r.q.tail(3), F_);
    for (const double x : {margin_, model_.internalForce(r.q.tail(3), F_), f_int_d, ctrl_.measured(), ctrl_.squeeze(), r.energy, r.work, r.residual})
      out.push_back(x);
  }
  void observe(const StepRecord& r) override { ctrl_.measure(r.q, F_); }
  // Under grasp control a contact that pulls, or leaves its cone, ends the run: a real fingertip would
  // have let go or slipped, and the pinned model beyond that point would teach the wrong thing.
  std::string stop(const StepRecord& r) override {
    if (s_.controller.kind != ControllerKind::Grasp || !(margin_ < 0)) return {};
    const std::string at = "contact " + std::to_string(worst_ + 1) + " at t = " + fmt("%.3g", r.t) + " s";
    if (worst_fn_ < 0) return "stopped: the grasp let go at " + at + " (the finger pulls: f_n = " + fmt("%.3g", worst_fn_) + " N)";
    return "stopped: the grasp slipped at " + at + " (|f_t| = " + fmt("%.3g", std::abs(worst_ft_)) + " N > μ f_n = " +
           fmt("%.3g", s_.params.mu * worst_fn_) + " N)";
  }

 private:
  // Each contact's force on the object (its constraint's force: the fingertip, body a, on the object).
  void contactForces(const StepRecord& r, VecN& F) const {
    F.resize(2 * model_.fingers());
    for (int i = 0; i < model_.fingers(); ++i) F.segment<2>(2 * i) = r.forces[std::size_t(i)].tail(2);
  }
  const Settings& s_;
  Controller ctrl_;
  Mechanism model_;
  VecN F_;
  double margin_ = INFINITY, worst_fn_ = 0, worst_ft_ = 0;
  int worst_ = 0;
};

}  // namespace

Settings parseSettings(const JsonView& c) {
  Settings s;
  c.onlyKeys({"lab", "title", "description", "variants", "mechanism", "model", "initial", "simulation", "controller", "gains", "reference",
              "disturbance", "metrics", "metric_docs", "rubric", "drawing", "submission_options", "map"});
  const JsonView m = c["mechanism"];
  m.onlyKeys({"fingers", "object", "joint_friction", "mu", "gravity"});
  const JsonView fingers = m["fingers"];
  const std::size_t count = fingers.size();
  if (count < 2 || count > 3) fingers.fail("expected 2 or 3 fingers (fewer cannot hold the object; more are not part of this lab)");
  for (std::size_t i = 0; i < count; ++i) s.params.fingers.push_back(parseFinger(fingers.at(i)));
  const JsonView o = m["object"];
  o.onlyKeys({"mass", "inertia", "size"});
  s.params.object.mass = o["mass"].positive(kMaxMass);
  o["size"].size(2, 2);
  s.params.object.size = {o["size"].at(0).positive(kMaxLength), o["size"].at(1).positive(kMaxLength)};
  const Eigen::Vector2d sz = s.params.object.size;
  s.params.object.inertia = o.has("inertia") ? o["inertia"].positive(kMaxMass) : s.params.object.mass * sz.squaredNorm() / 12.0;
  if (m.has("joint_friction")) {
    const JsonView jf = m["joint_friction"];
    jf.onlyKeys({"viscous", "coulomb", "coulomb_width"});
    s.params.joint.viscous = jf["viscous"].inRange(0, kMaxForce);
    s.params.joint.coulomb = jf["coulomb"].inRange(0, kMaxForce);
    if (jf.has("coulomb_width")) s.params.joint.coulomb_width = jf["coulomb_width"].positive(1e3);
  }
  if (!(m["mu"].number() > 0))
    m["mu"].fail("expected a friction coefficient μ > 0 (a contact without friction cannot hold the object up)");
  s.params.mu = m["mu"].positive(100);
  s.params.gravity = vec2(m["gravity"], -kMaxGravity, kMaxGravity);

  // The controller's model: the plant's fingers and gravity, its own object and friction coefficient.
  const JsonView md = c["model"];
  md.onlyKeys({"object", "mu"});
  const JsonView mo = md["object"];
  mo.onlyKeys({"mass", "inertia"});
  s.model = s.params;
  s.model.object.mass = mo["mass"].positive(kMaxMass);
  s.model.object.inertia = mo.has("inertia") ? mo["inertia"].positive(kMaxMass) : s.model.object.mass * sz.squaredNorm() / 12.0;
  s.model.mu = md["mu"].positive(100);

  const JsonView init = c["initial"];
  init.onlyKeys({"x", "y", "psi_deg"});
  s.pose0 = {init["psi_deg"].inRange(-180, 180) * M_PI / 180.0, init["x"].inRange(-kMaxLength, kMaxLength),
             init["y"].inRange(-kMaxLength, kMaxLength)};

  const SimulationSettings sim = parseSimulation(c["simulation"], IndependentForm::Yes);  // recoverDependent
  s.step = sim.step;
  s.duration = sim.duration;

  const JsonView ctl = c["controller"];
  ctl.onlyKeys({"kind", "torques", "delay", "noise_std", "seed"});
  auto& cc = s.controller;
  const std::string kind = ctl["kind"].oneOf({"none", "constant", "grasp"});
  cc.kind = kind == "none" ? ControllerKind::None : kind == "constant" ? ControllerKind::Constant : ControllerKind::Grasp;
  if (cc.kind == ControllerKind::Constant) {
    const JsonView t = ctl["torques"];
    if (t.size() != 2 * count) t.fail("expected one torque per joint (" + std::to_string(2 * count) + " numbers, N·m)");
    for (std::size_t i = 0; i < 2 * count; ++i) cc.torques.push_back(t.at(i).inRange(-kMaxForce, kMaxForce));
  }
  cc.delay = ctl.has("delay") ? ctl["delay"].inRange(0, 1) : 0.0;
  cc.noise_std = ctl.has("noise_std") ? ctl["noise_std"].inRange(0, kMaxForce) : 0.0;
  cc.seed = ctl.has("seed") ? std::uint64_t(ctl["seed"].integer(0, 1LL << 53)) : 1;
  const auto g = parseGains(c["gains"], {"kp_pos", "kd_pos", "kp_psi", "kd_psi", "f_squeeze", "ki_int", "k_cone"});
  cc.gains = {g.at("kp_pos"), g.at("kd_pos"), g.at("kp_psi"), g.at("kd_psi"), g.at("f_squeeze"), g.at("ki_int"), g.at("k_cone")};

  const JsonView ref = c["reference"];
  ref.onlyKeys({"lift", "lift_time", "hold", "sideways", "tilt_deg", "period"});
  auto& r = s.reference;
  r.pose0 = s.pose0;
  r.lift = ref["lift"].inRange(-kMaxLength, kMaxLength);
  r.lift_time = ref["lift_time"].inRange(1e-3, 1e6);
  r.hold = ref["hold"].inRange(0, 1e6);
  r.sideways = ref["sideways"].inRange(-kMaxLength, kMaxLength);
  r.tilt = ref["tilt_deg"].inRange(-90, 90) * M_PI / 180.0;
  r.period = ref["period"].inRange(1e-3, 1e6);

  if (c.has("disturbance")) {
    const JsonView d = c["disturbance"];
    d.onlyKeys({"force", "start", "duration"});
    s.push.force = vec2(d["force"], -kMaxForce, kMaxForce);
    s.push.start = d["start"].inRange(0, 1e6);
    s.push.duration = d["duration"].inRange(0, 1e6);
  }
  parseMetricsAndDrawing(c, s.settle_time, s.arrow_scale);
  // The fingers must reach their contact points, and the contacts must hold the object in every direction.
  const Mechanism mech(s.params);
  VecN q, v;
  std::string why;
  if (!mech.assemble(s.pose0, Eigen::Vector3d::Zero(), q, v, &why)) init.fail("expected an object pose the fingers can reach: " + why);
  MatN G;
  VecN d;
  mech.graspMap(s.pose0, G, d);
  if (std::abs((G * G.transpose()).determinant()) < 1e-12 || d.squaredNorm() < 1e-12)
    fingers.fail("expected contact points that hold the object (two distinct points with opposing normals, or more)");
  return s;
}

GraspLab::GraspLab(Settings s) : SettingsLab(std::move(s)) {
  columns_ = makeColumns(fingers());
  // The units of the object's and the whole grasp's columns; unit() adds the fingers' (q*, tau*, f*).
  units_ = {
      {"t", "s"},      {"x_o", "m"},       {"y_o", "m"},         {"psi_o", "rad"},   {"vx_o", "m/s"},  {"vy_o", "m/s"},
      {"w_o", "rad/s"}, {"x_d", "m"},      {"y_d", "m"},         {"psi_d", "rad"},   {"cone_margin", "N"},
      {"f_int", "N"},  {"f_int_d", "N"}, {"f_int_meas", "N"}, {"squeeze", "N"},    {"energy", "J"},    {"work", "J"},
      {"constraint_residual", "m"}};
  agreement_units_ = {
      {"max_dq", "rad"}, {"max_dpos", "m"}, {"max_dpsi", "rad"}, {"max_dnet_force", "N"}, {"max_df_int", "N"}};
  // Passive (τ = 0, no joint friction) the fingers and the object fall together for 2 s, through the
  // configuration where both fingers hang straight (t ≈ 0.35, 0.93, 1.62 s: the accelerations peak there).
  // RK4 + projection at dt 1 ms keeps E within 2.5e-6·|E0| (1.9e-6 measured); at 0.5 ms within 1e-6, 16× less
  // (fourth order; tests/labs/grasp_test.cpp).
  passive_ = {2.5e-6, 2.0, {{"mechanism", {{"joint_friction", nullptr}}}}};
}

std::string GraspLab::unit(const std::string& c) const {
  if (std::string u = SettingsLab::unit(c); !u.empty()) return u;
  if (c.size() > 1 && c[0] == 'q' && std::isdigit(static_cast<unsigned char>(c[1]))) return "rad";
  if (c.rfind("tau", 0) == 0) return "N·m";
  if (c.size() > 2 && c[0] == 'f' && std::isdigit(static_cast<unsigned char>(c[1]))) return "N";
  return {};
}

std::unique_ptr<Simulation> GraspLab::simulate(Engine engine) const {
  // The push on the object's centre of mass: an external force the engines evaluate inside each step.
  Params params = s_.params;
  if (s_.push.force != Eigen::Vector2d::Zero() && s_.push.duration > 0)
    params.forces.push_back(std::make_shared<PushForce<Planar>>(BodyRef::payload(0), Planar::Pos::Zero(),
                                                                 Planar::Vec(0.0, s_.push.force.x(), s_.push.force.y()),
                                                                 ForceProfile{s_.push.start, 0.0, s_.push.duration}));
  // The start pose assembled by the mechanism that steps it (built once). Two fingers (the default)
  // at fixed sizes: the step's loops unrolled (mechanism.h TwoFingers).
  VecN q, v;
  if (params.fingers.size() == 2) {
    auto mech = std::make_unique<TwoFingers>(params);
    mech->shape().assemble(s_.pose0, Eigen::Vector3d::Zero(), q, v);
    return simulateMechanism(engine, std::move(mech), s_.step, q, v, std::make_unique<Hooks>(s_, q, v), columns_, s_.duration);
  }
  auto mech = std::make_unique<Mechanism>(params);
  mech->assemble(s_.pose0, Eigen::Vector3d::Zero(), q, v);
  return simulateMechanism(engine, std::move(mech), s_.step, q, v, std::make_unique<Hooks>(s_, q, v), columns_, s_.duration);
}

MujocoTwin GraspLab::mujocoTwin() const {
  MujocoTwin t;
  t.file = "mujoco.xml";
  t.stands_in = "the point contacts as MuJoCo connects (both ways, frictionless; soft)";
  Mechanism mech(s_.params);
  mech.assemble(s_.pose0, Eigen::Vector3d::Zero(), t.q, t.v);
  // The file's object coordinates (x, y, ψ): slides before the hinge, whose axis they would turn.
  const int n = int(t.q.size()) - 3;
  for (int i = 0; i < n; ++i) t.order.push_back(i);
  t.order.insert(t.order.end(), {n + 1, n + 2, n});
  t.dynamics = handDynamics(describe(s_.params));
  return t;
}

json GraspLab::metrics(const Trace& tr) const {
  std::vector<double> ep, epsi, ef;
  double margin = INFINITY, margin_t = 0, tau_max = 0, drift = 0, residual = 0, ep_max = 0;
  const auto t_col = tr.col("t"), x_o = tr.col("x_o"), x_d = tr.col("x_d"), y_o = tr.col("y_o"), y_d = tr.col("y_d");
  const auto psi_o = tr.col("psi_o"), psi_d = tr.col("psi_d"), f_int = tr.col("f_int"), f_int_d = tr.col("f_int_d");
  const auto cone_margin = tr.col("cone_margin"), energy = tr.col("energy"), work = tr.col("work");
  const auto residual_col = tr.col("constraint_residual");
  const double e0 = tr.rows() ? tr.at(0, "energy") : 0;
  std::vector<Trace::Column> taus;
  for (int j = 1; j <= 2 * fingers(); ++j) taus.push_back(tr.col("tau" + std::to_string(j)));
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    const double ex = x_o[r] - x_d[r], ey = y_o[r] - y_d[r];
    ep.push_back(det::hypot(ex, ey));
    ep_max = std::max(ep_max, ep.back());
    epsi.push_back(psi_o[r] - psi_d[r]);
    if (t_col[r] >= s_.settle_time) ef.push_back(f_int[r] - f_int_d[r]);
    if (cone_margin[r] < margin) margin = cone_margin[r], margin_t = t_col[r];
    for (const auto& tau : taus) tau_max = std::max(tau_max, std::abs(tau[r]));
    // Energy balance: E − E0 − ∫ (τ·θ' + push·v_o) dt (zero for exact dynamics).
    drift = std::max(drift, std::abs(energy[r] - e0 - work[r]));
    residual = std::max(residual, residual_col[r]);
  }
  return {{"pos_rms", rms(ep)},          {"pos_max_error", ep_max},
          {"psi_rms", rms(epsi)},        {"cone_margin_min", tr.rows() ? margin : 0.0},
          {"cone_margin_time", margin_t}, {"f_int_rms", rms(ef)},
          {"tau_max", tau_max},          {"energy_drift", drift},
          {"energy_initial", e0},        {"max_constraint_residual", residual},
          {"steps", tr.steps()},          {"settle_time", s_.settle_time}};
}

json GraspLab::differences(const Trace& a, const Trace& b, std::size_t n) const {
  double dq = 0, dpos = 0, dpsi = 0, dnet = 0, dint = 0;
  const int m = fingers();
  for (std::size_t r = 0; r < n; ++r) {
    for (int j = 1; j <= 2 * m; ++j) dq = std::max(dq, std::abs(a.at(r, "q" + std::to_string(j)) - b.at(r, "q" + std::to_string(j))));
    dpos = std::max(dpos, det::hypot(a.at(r, "x_o") - b.at(r, "x_o"), a.at(r, "y_o") - b.at(r, "y_o")));
    dpsi = std::max(dpsi, std::abs(a.at(r, "psi_o") - b.at(r, "psi_o")));
    // The net force on the object is determined by its motion; the squeeze only by the fingers' dynamics.
    Eigen::Vector2d net = Eigen::Vector2d::Zero();
    for (int i = 1; i <= m; ++i) {
      const std::string f = "f" + std::to_string(i);
      net += Eigen::Vector2d(a.at(r, f + "_x") - b.at(r, f + "_x"), a.at(r, f + "_y") - b.at(r, f + "_y"));
    }
    dnet = std::max(dnet, net.norm());
    dint = std::max(dint, std::abs(a.at(r, "f_int") - b.at(r, "f_int")));
  }
  return {{"max_dq", dq}, {"max_dpos", dpos}, {"max_dpsi", dpsi}, {"max_dnet_force", dnet}, {"max_df_int", dint}};
}

DYNLAB_REGISTER_LAB(grasp, "Multi-finger grasp: carry an object held by two fingers, squeezing just enough to stay inside every friction cone",
                    labFactory<GraspLab>(parseSettings));

}  // namespace dyn::grasp
