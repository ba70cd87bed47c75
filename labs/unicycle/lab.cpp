// Unicycle lab: parses unicycle.json, runs the hand-written model (eq. (2) with the rolling kind) or the
// Bullet no-slip reference with the same controller — beside which the Bullet run also drives Bullet's
// friction-contact wheel, which can skid — and measures the runs.
#include "labs/unicycle/lab.h"

#include <cmath>

#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "labs/settings.h"
#include "physics/constraints/rolling.h"
#include "physics/det/det.h"

namespace dyn::unicycle {
namespace {

constexpr double kMaxLength = 100, kMaxMass = 1e3, kMaxGravity = 1e3, kMaxTorque = 1e3, kMaxRate = 1e3;

// The one place the trace row is laid out. The *_fric columns are Bullet's friction-contact wheel,
// driven by its own copy of the controller; in the hand trace they repeat the no-slip wheel's own.
const std::vector<std::string> kColumns = {
    "t",          "x",          "y",         "phi",        "theta",      "phi_rate",   "theta_rate", "tau_drive",
    "tau_steer",  "f_long",     "f_lat",     "f_normal",   "skid_margin", "slip",      "x_d",        "y_d",
    "phi_d",      "v_d",        "speed",     "speed_meas", "cross_track", "s_d",       "energy",     "work",
    "constraint_residual", "x_fric", "y_fric", "phi_fric", "slip_fric", "f_lat_fric"};

// The contact force's wheel-axes parts and skid margin (f on the wheel, world axes) at heading φ.
void wheelForces(const Eigen::Vector3d& f, double phi, double mu, double out[4]) {
  Rolling::contactAxes(f, Eigen::Vector3d(-det::sin(phi), det::cos(phi), 0), mu, out);
}

// Bullet's friction-contact wheel, stepped beside the Bullet run with its own controller.
class FrictionWheel {
 public:
  FrictionWheel(const Settings& s, const Path& path, const Mechanism& mech, const VecN& q0, const VecN& v0)
      : s_(s), mech_(mech), ctrl_(s.controller, path, s.reference, s.params.radius, s.step.dt), q_(q0), v_(v0),
        world_(frictionModel(s.params), s.step.dt, q0, v0) {}
  // Writes x, y, φ, slip at t and f_lat over the step, then steps.
  void step(double t, double out[5]) {
    const VecN tau = ctrl_.torque(t, q_, v_);
    world_.step(tau);
    double f[4];
    wheelForces(Spatial::linear(world_.constraintForce(0)), q_[Phi], s_.params.mu, f);
    out[0] = q_[X], out[1] = q_[Y], out[2] = q_[Phi], out[3] = slip_, out[4] = f[1];
    // The contact's slip over the step: Bullet's contact held at the step's start heading, so the new
    // velocities are measured against it (at the new heading a gripping wheel would read v φ' dt).
    const double phi_start = q_[Phi];
    world_.state(q_, v_);
    VecN q_start = q_;
    q_start[Phi] = phi_start;
    slip_ = mech_.slipSpeed(q_start, v_);
  }

 private:
  static MechanismModel<Spatial> frictionModel(const Params& p) {
    MechanismModel<Spatial> d = describe(p);
    d.bullet.rolling = RollingModel::Friction;
    return d;
  }
  const Settings& s_;
  const Mechanism& mech_;
  Controller ctrl_;
  VecN q_, v_;
  double slip_ = 0;
  bullet::BulletMechanism<Spatial> world_;
};

// The lab's part of a run on either engine (labs/mechanism_simulation.h).
class Hooks final : public StepHooks {
 public:
  Hooks(const Settings& s, const Path& path, Engine engine, const VecN& q0, const VecN& v0)
      : s_(s), mech_(s.params), ctrl_(s.controller, path, s.reference, s.params.radius, s.step.dt) {
    if (engine == Engine::Bullet) friction_ = std::make_unique<FrictionWheel>(s, path, mech_, q0, v0);
  }
  VecN torque(double t, const VecN& q, const VecN& v) override { return ctrl_.torque(t, q, v); }
  void row(const StepRecord& r, std::vector<double>& out) override {
    const double r_w = s_.params.radius;
    double f[4];
    wheelForces(Spatial::linear(r.forces[0]), r.q[Phi], s_.params.mu, f);
    const double slip = mech_.slipSpeed(r.q, r.v);
    const Target& d = ctrl_.target();
    out = {r.t, r.q[X], r.q[Y], r.q[Phi], r.q[Theta], r.v[Phi], r.v[Theta], r.tau[Theta], r.tau[Phi], f[0], f[1], f[2], f[3],
           slip, d.p.x(), d.p.y(), d.heading, d.speed, r_w * r.v[Theta], r_w * ctrl_.measuredSpeed(), d.cross_track,
           d.s, r.energy, r.work, r.residual};
    double fr[5] = {r.q[X], r.q[Y], r.q[Phi], slip, f[1]};
    if (friction_) friction_->step(r.t, fr);
    out.insert(out.end(), fr, fr + 5);
  }

 private:
  const Settings& s_;
  Mechanism mech_;
  Controller ctrl_;
  std::unique_ptr<FrictionWheel> friction_;
};

std::vector<Eigen::Vector2d> parsePoints(const JsonView& j) {
  if (!j.raw().is_array()) j.fail("expected the path as a list of points [[x, y], ...] in metres");
  const std::size_t n = j.size(2, 10000);
  std::vector<Eigen::Vector2d> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const JsonView p = j.at(i);
    if (!p.raw().is_array() || p.raw().size() != 2) p.fail("expected a point [x, y] in metres");
    pts.emplace_back(p.at(0).inRange(-kMaxLength, kMaxLength), p.at(1).inRange(-kMaxLength, kMaxLength));
    if (i > 0 && (pts[i] - pts[i - 1]).norm() < 1e-6) p.fail("expected a point distinct from the one before it");
  }
  return pts;
}

}  // namespace

Settings parseSettings(const JsonView& c) {
  Settings s;
  c.onlyKeys({"lab", "title", "description", "variants", "mechanism", "initial", "simulation", "controller", "gains", "reference",
              "metrics", "metric_docs", "rubric", "drawing", "submission_options", "map", "figures"});
  const JsonView m = c["mechanism"];
  m.onlyKeys({"radius", "mass", "axle_inertia", "steer_inertia", "mu", "gravity"});
  auto& p = s.params;
  if (!(m["radius"].number() > 0)) m["radius"].fail("expected the wheel radius r > 0 (m)");
  p.radius = m["radius"].positive(kMaxLength);
  p.mass = m["mass"].positive(kMaxMass);
  // A uniform disk unless given: I_a = m r²/2, I_z = m r²/4.
  p.axle_inertia = m.has("axle_inertia") ? m["axle_inertia"].positive(kMaxMass) : p.mass * p.radius * p.radius / 2;
  p.steer_inertia = m.has("steer_inertia") ? m["steer_inertia"].positive(kMaxMass) : p.mass * p.radius * p.radius / 4;
  if (!(m["mu"].number() >= 0)) m["mu"].fail("expected a friction coefficient μ ≥ 0");
  p.mu = m["mu"].inRange(0, 100);
  p.gravity = m["gravity"].inRange(0, kMaxGravity);

  const JsonView init = c["initial"];
  init.onlyKeys({"x", "y", "phi_deg", "phi_rate", "theta_rate"});
  s.x0 = init["x"].inRange(-kMaxLength, kMaxLength);
  s.y0 = init["y"].inRange(-kMaxLength, kMaxLength);
  s.phi0 = init["phi_deg"].inRange(-360, 360) * M_PI / 180.0;
  s.phi_rate0 = init.has("phi_rate") ? init["phi_rate"].inRange(-kMaxRate, kMaxRate) : 0.0;
  s.theta_rate0 = init.has("theta_rate") ? init["theta_rate"].inRange(-kMaxRate, kMaxRate) : 0.0;

  const SimulationSettings sim = parseSimulation(c["simulation"]);
  s.step = sim.step;
  s.duration = sim.duration;

  const JsonView ctl = c["controller"];
  ctl.onlyKeys({"kind", "tau_drive", "tau_steer", "delay", "speed_noise", "seed"});
  auto& cc = s.controller;
  const std::string kind = ctl["kind"].oneOf({"none", "constant", "path"});
  cc.kind = kind == "none" ? ControllerKind::None : kind == "constant" ? ControllerKind::Constant : ControllerKind::Path;
  if (cc.kind == ControllerKind::Constant) {
    cc.tau_drive = ctl["tau_drive"].inRange(-kMaxTorque, kMaxTorque);
    cc.tau_steer = ctl["tau_steer"].inRange(-kMaxTorque, kMaxTorque);
  }
  cc.delay = ctl.has("delay") ? ctl["delay"].inRange(0, 1) : 0.0;
  cc.speed_noise = ctl.has("speed_noise") ? ctl["speed_noise"].inRange(0, kMaxRate) : 0.0;
  cc.seed = ctl.has("seed") ? std::uint64_t(ctl["seed"].integer(0, 1LL << 53)) : 1;
  const auto g = parseGains(c["gains"], {"kp_speed", "ki_speed", "kp_heading", "kd_heading", "k_cross", "a_lat"});
  cc.gains = {g.at("kp_speed"), g.at("ki_speed"), g.at("kp_heading"), g.at("kd_heading"), g.at("k_cross"), g.at("a_lat")};
  if (!(cc.gains.a_lat > 0)) c["gains"]["a_lat"].fail("expected a cornering limit a_lat > 0 (m/s²): the leader must be able to turn");

  const JsonView ref = c["reference"];
  ref.onlyKeys({"points", "speed", "accel"});
  s.reference.points = parsePoints(ref["points"]);
  s.reference.speed = ref["speed"].positive(100);
  s.reference.accel = ref["accel"].positive(1e3);

  if (c.has("metrics")) c["metrics"].onlyKeys({});
  if (c.has("drawing")) {
    c["drawing"].onlyKeys({"arrow_scale"});
    s.arrow_scale = c["drawing"]["arrow_scale"].positive(1e3);
  }
  return s;
}

UnicycleLab::UnicycleLab(Settings s) : SettingsLab(std::move(s)), path_(s_.reference.points) {
  columns_ = kColumns;
  units_ = {
      {"t", "s"},          {"x", "m"},           {"y", "m"},           {"phi", "rad"},         {"theta", "rad"},
      {"phi_rate", "rad/s"}, {"theta_rate", "rad/s"}, {"tau_drive", "N·m"}, {"tau_steer", "N·m"}, {"f_long", "N"},
      {"f_lat", "N"},      {"f_normal", "N"},    {"skid_margin", "N"}, {"slip", "m/s"},        {"x_d", "m"},
      {"y_d", "m"},        {"phi_d", "rad"},     {"v_d", "m/s"},       {"speed", "m/s"},       {"speed_meas", "m/s"},
      {"cross_track", "m"}, {"s_d", "m"},        {"energy", "J"},      {"work", "J"},          {"constraint_residual", "m/s"},
      {"x_fric", "m"},     {"y_fric", "m"},      {"phi_fric", "rad"},  {"slip_fric", "m/s"},   {"f_lat_fric", "N"}};
  agreement_units_ = {
      {"max_dpos", "m"},       {"max_dphi", "rad"},         {"max_dtheta_rate", "rad/s"}, {"max_df_lat", "N"},
      {"max_df_normal", "N"},  {"bullet_max_slip", "m/s"}, {"friction_max_slip", "m/s"}, {"friction_max_dpos", "m"}};
  // Passive (τ = 0) the wheel rolls on at its initial rates; with none it stands still, so the check's
  // patch gives it some: a circle of radius r θ'/φ'. The rolling rows do no work: E stays put to RK4's
  // accuracy (tests/labs/unicycle_test.cpp measures it).
  passive_ = {1e-9, 0.0, {{"initial", {{"theta_rate", 20.0}, {"phi_rate", 1.5}}}}};
}

std::unique_ptr<Simulation> UnicycleLab::simulate(Engine engine) const {
  auto mech = std::make_unique<Mechanism>(s_.params);
  VecN q, v;
  mech->state(s_.x0, s_.y0, s_.phi0, 0.0, s_.phi_rate0, s_.theta_rate0, q, v);
  return simulateMechanism(engine, std::move(mech), s_.step, q, v, std::make_unique<Hooks>(s_, path_, engine, q, v), kColumns, s_.duration);
}

MujocoTwin UnicycleLab::mujocoTwin() const {
  MujocoTwin t;
  t.file = "mujoco.xml";
  t.stands_in = "rolling without slip as MuJoCo's frictional contact of the wheel on the ground (mu 0.8, soft: MuJoCo has no velocity-level row)";
  t.contacts = true;
  Mechanism(s_.params).state(s_.x0, s_.y0, s_.phi0, 0.0, s_.phi_rate0, s_.theta_rate0, t.q, t.v);
  t.dynamics = handDynamics(describe(s_.params));
  return t;
}

json UnicycleLab::metrics(const Trace& tr) const {
  std::vector<double> ect, epos, ev;
  double margin = INFINITY, margin_t = 0, f_lat = 0, tau_y = 0, tau_z = 0, drift = 0, residual = 0, ect_max = 0;
  const auto t_col = tr.col("t"), cross_track = tr.col("cross_track"), x = tr.col("x"), x_d = tr.col("x_d");
  const auto y = tr.col("y"), y_d = tr.col("y_d"), speed = tr.col("speed"), v_d = tr.col("v_d");
  const auto skid_margin = tr.col("skid_margin"), f_lat_col = tr.col("f_lat"), tau_drive = tr.col("tau_drive");
  const auto tau_steer = tr.col("tau_steer"), energy = tr.col("energy"), work = tr.col("work");
  const auto residual_col = tr.col("constraint_residual");
  const double e0 = tr.rows() ? tr.at(0, "energy") : 0;
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    ect.push_back(cross_track[r]);
    ect_max = std::max(ect_max, std::abs(ect.back()));
    epos.push_back(det::hypot(x[r] - x_d[r], y[r] - y_d[r]));
    ev.push_back(speed[r] - v_d[r]);
    if (skid_margin[r] < margin) margin = skid_margin[r], margin_t = t_col[r];
    f_lat = std::max(f_lat, std::abs(f_lat_col[r]));
    tau_y = std::max(tau_y, std::abs(tau_drive[r]));
    tau_z = std::max(tau_z, std::abs(tau_steer[r]));
    drift = std::max(drift, std::abs(energy[r] - e0 - work[r]));
    residual = std::max(residual, residual_col[r]);
  }
  const double progress = tr.rows() ? tr.at(tr.rows() - 1, "s_d") / path_.length() : 0.0;
  return {{"cross_track_rms", rms(ect)}, {"cross_track_max", ect_max},  {"pos_rms", rms(epos)},
          {"speed_rms", rms(ev)},        {"skid_margin_min", tr.rows() ? margin : 0.0}, {"skid_margin_time", margin_t},
          {"f_lat_max", f_lat},          {"tau_drive_max", tau_y},      {"tau_steer_max", tau_z},
          {"progress", progress},        {"energy_drift", drift},      {"energy_initial", e0},
          {"max_constraint_residual", residual}, {"steps", tr.steps()}};
}

json UnicycleLab::differences(const Trace& a, const Trace& b, std::size_t n) const {
  double dpos = 0, dphi = 0, drate = 0, dlat = 0, dnormal = 0, slip = 0, slip_fric = 0, dpos_fric = 0;
  for (std::size_t r = 0; r < n; ++r) {
    dpos = std::max(dpos, det::hypot(a.at(r, "x") - b.at(r, "x"), a.at(r, "y") - b.at(r, "y")));
    dphi = std::max(dphi, std::abs(a.at(r, "phi") - b.at(r, "phi")));
    drate = std::max(drate, std::abs(a.at(r, "theta_rate") - b.at(r, "theta_rate")));
    dlat = std::max(dlat, std::abs(a.at(r, "f_lat") - b.at(r, "f_lat")));
    dnormal = std::max(dnormal, std::abs(a.at(r, "f_normal") - b.at(r, "f_normal")));
    slip = std::max(slip, b.at(r, "slip"));
    slip_fric = std::max(slip_fric, b.at(r, "slip_fric"));
    dpos_fric = std::max(dpos_fric, det::hypot(a.at(r, "x") - b.at(r, "x_fric"), a.at(r, "y") - b.at(r, "y_fric")));
  }
  return {{"max_dpos", dpos},        {"max_dphi", dphi},              {"max_dtheta_rate", drate},
          {"max_df_lat", dlat},      {"max_df_normal", dnormal},      {"bullet_max_slip", slip},
          {"friction_max_slip", slip_fric}, {"friction_max_dpos", dpos_fric}};
}

DYNLAB_REGISTER_LAB(unicycle, "Rolling unicycle: drive a wheel along a path without skidding (a nonholonomic constraint)",
                    labFactory<UnicycleLab>(parseSettings));

}  // namespace dyn::unicycle
