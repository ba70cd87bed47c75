// Pen-on-table lab: parses pen_on_table.json, runs the hand-written model (eq. (3) with the unilateral
// plane contact: lift-off between steps, touchdown located inside its step) or the Bullet reference
// (the tip a sphere on a static plane) with the same controller, and measures the runs.
#include "labs/pen_on_table/lab.h"

#include <algorithm>
#include <cmath>

#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "labs/settings.h"
#include "physics/det/det.h"

namespace dyn::pen_on_table {
namespace {

constexpr double kMaxLength = 10, kMaxMass = 1e3, kMaxGravity = 1e3, kMaxTorque = 1e3, kMaxRate = 1e3, kMaxForce = 1e3;
// The workspace the circle must lie in: the elbow at least this far from stretched or folded
// (|sin θ3| ≥ 0.25, θ3 within 14.5° … 165.5°) and the tip this far from the base axis (θ1 defined).
constexpr double kMinElbowSine = 0.25, kMinAxisDistance = 0.05;
// s: the window of f_z_5ms, the force's trailing mean (an impact's impulse P reads P / 5 ms at any dt).
constexpr double kImpactWindow = 0.005;

// The one place the trace row is laid out.
const std::vector<std::string> kColumns = {"t",     "q1",    "q2",     "q3",      "tau1",  "tau2",   "tau3",
                                           "x_p",   "y_p",   "z_p",    "x_d",     "y_d",   "z_des",  "f_z",
                                           "f_zd",  "f_meas", "contact", "gap",   "energy", "work", "constraint_residual",
                                           "f_z_5ms"};

// The arm the controller believes in: without the pen's extra load, the table where it expects it.
Params believed(const Params& p, const ControllerConfig& c) {
  Params b = p;
  b.pen_load = 0;
  b.table_height = c.table_assumed;
  return b;
}

// Lift-offs after the first touchdown (the table stops pushing: contact 1 → 0), told apart by when
// they come: before the pen first stayed on the table for `settle` s (it bounced on touchdown: the
// impact's impulse reaches the force sensor and the force law moves z_des by it), or after (the
// pressed loop lost the table). The watchdog and the metrics count them alike, row by row.
struct Liftoffs {
  double settle;
  bool touched = false, in_contact = false, settled = false;
  double since = 0;  // when the current contact began
  int on_touchdown = 0, pressed = 0;
  // One row; true on a lift-off.
  bool step(double t, bool contact) {
    const bool lift = touched && in_contact && !contact;
    if (lift) ++(settled ? pressed : on_touchdown);
    if (contact && !in_contact) since = t;
    if (contact && t - since >= settle - 1e-9) settled = true;
    touched = touched || contact;
    in_contact = contact;
    return lift;
  }
  int total() const { return on_touchdown + pressed; }
};

// The lab's part of a run on either engine (labs/mechanism_simulation.h).
// hand: the hand engine's mechanism (its impact impulses), null for Bullet.
class Hooks final : public StepHooks {
 public:
  Hooks(const Settings& s, double z0, const Mechanism* hand)
      : s_(s), mech_(s.params), ctrl_(s.controller, s.circle, believed(s.params, s.controller), s.step.dt, z0), hand_(hand),
        window_(std::size_t(std::max(1L, std::lround(kImpactWindow / s.step.dt))), 0.0) {}
  VecN torque(double t, const VecN& q, const VecN& v) override { return ctrl_.torque(t, q, v); }
  // The step's mean force along ẑ: the table's push η (the solve at the step's start; Bullet: its
  // impulses over the step / dt) plus, on the hand engine, a touchdown's impact impulse P / dt (the
  // plastic impact is a velocity jump at the touchdown located inside the step, eq. (2) for impulses),
  // as Bullet and the impedance lab's wall count it.
  double push(const StepRecord& r) const {
    const double eta = Spatial::linear(r.forces[0]).z();
    return hand_ ? eta + Spatial::linear(hand_->impactImpulse(0)).z() / s_.step.dt : eta;
  }
  void row(const StepRecord& r, std::vector<double>& out) override {
    // f_z: the force the pen applies to the table (the lecture's sign), −η of the table's push; and its
    // mean over the last 5 ms (the impulse spread over a window of fixed length, whatever dt).
    const double eta = push(r), f_z = -eta;
    sum_ += f_z - window_[next_];
    window_[next_] = f_z;
    next_ = (next_ + 1) % window_.size();
    const Eigen::Vector3d p = mech_.tip(r.q);
    const double gap = p.z() - s_.params.table_height;
    // Bullet's rows are not the hand model's: on a rigid table its residual is the tip's penetration.
    const double residual = std::max(r.residual, s_.params.table_stiffness > 0 ? 0.0 : std::max(0.0, -gap));
    const Target& d = ctrl_.target();
    out = {r.t,       r.q[0],      r.q[1],      r.q[2],    r.tau[0], r.tau[1], r.tau[2],         p.x(),
           p.y(),     p.z(),       d.p.x(),     d.p.y(),   d.p.z(),  f_z,      s_.controller.f_zd, d.f_meas,
           eta > 0 ? 1.0 : 0.0,    gap,         r.energy,  r.work,   residual, sum_ / double(window_.size())};
  }
  void observe(const StepRecord& r) override { ctrl_.measure(-push(r)); }
  // The lab's watchdog: an unstable force loop on a unilateral contact does not blow up, it hammers the
  // table (a bounded limit cycle of lift-offs); the run stops at max_liftoffs (4) of them after the first
  // touchdown. Its verdict names what the trace shows: lift-offs before the pen ever settled (pressed
  // for the overshoot window) are a bounce on touchdown, any after it the pressed loop oscillating.
  std::string stop(const StepRecord& r) override {
    if (!lifts_.step(r.t, push(r) > 0) || lifts_.total() < s_.max_liftoffs) return {};
    const std::string at = " at t = " + fmt("%.4g", r.t) + " s";
    if (lifts_.pressed > 0)
      return "stopped: the pressed loop oscillates (the pen lost the table " + std::to_string(lifts_.pressed) + " of " +
             std::to_string(lifts_.total()) + " times after it had settled)" + at;
    const std::string kick = s_.controller.law == ForceLaw::Damper ? "the damper moves z_des by P/D_z" : "the spring kicks z_des by its reading over K_z";
    return "stopped: the pen bounced on touchdown (" + std::to_string(lifts_.total()) + " lift-offs before it settled)" + at +
           " (the impact's impulse P reaches the force sensor and " + kick + "; near its delay margin the force loop keeps it bouncing)";
  }

 private:
  const Settings& s_;
  Mechanism mech_;
  Controller ctrl_;
  const Mechanism* hand_;
  std::vector<double> window_;  // the last 5 ms of f_z (a ring)
  std::size_t next_ = 0;
  double sum_ = 0;
  Liftoffs lifts_{s_.overshoot_window};
};

Link parseLink(const JsonView& j) {
  j.onlyKeys({"length", "mass", "radius"});
  return {j["length"].positive(kMaxLength), j["mass"].positive(kMaxMass), j["radius"].positive(1.0)};
}

// Where the circle (or the start point) leaves the workspace: empty if nowhere, else the reason.
std::string outOfReach(const Params& p, const Eigen::Vector3d& tip) {
  const double R = det::hypot(tip.x(), tip.y());
  const double d = det::hypot(R, tip.z() + p.tip_radius - p.links[0].length);
  if (R < kMinAxisDistance) return "is " + fmt("%.3g", R) + " m from the base axis (at least 0.05 m keeps θ1 defined)";
  if (elbowSine(p, tip) < kMinElbowSine)
    return "is " + fmt("%.3g", d) + " m from the shoulder (the arm reaches " + fmt("%.3g", std::abs(p.links[1].length - p.links[2].length)) +
           " to " + fmt("%.3g", p.links[1].length + p.links[2].length) + " m; the elbow must stay 14.5° from stretched or folded)";
  return {};
}

}  // namespace

Settings parseSettings(const JsonView& c) {
  Settings s;
  c.onlyKeys({"lab", "title", "description", "variants", "mechanism", "table", "initial", "simulation", "controller", "gains", "reference",
              "metrics", "metric_docs", "rubric", "drawing", "submission_options", "map", "figures"});
  // The arm.
  const JsonView m = c["mechanism"];
  m.onlyKeys({"links", "tip_radius", "pen_load", "gravity"});
  auto& p = s.params;
  m["links"].size(3, 3);
  for (std::size_t i = 0; i < 3; ++i) p.links[i] = parseLink(m["links"].at(i));
  p.tip_radius = m["tip_radius"].inRange(0, 0.1);
  p.pen_load = m.has("pen_load") ? m["pen_load"].inRange(0, kMaxMass) : 0.0;
  p.gravity = m["gravity"].inRange(0, kMaxGravity);
  // The table.
  const JsonView tb = c["table"];
  tb.onlyKeys({"height", "stiffness", "damping", "mu"});
  p.table_height = tb["height"].inRange(-kMaxLength, kMaxLength);
  p.table_stiffness = tb.has("stiffness") ? tb["stiffness"].inRange(0, 1e9) : 0.0;
  p.table_damping = tb.has("damping") ? tb["damping"].inRange(0, 1e7) : 0.0;
  if (p.table_damping > 0 && p.table_stiffness == 0)
    tb["damping"].fail("expected 0 on a rigid table (stiffness 0): damping belongs to a compliant table");
  p.mu = tb.has("mu") ? tb["mu"].inRange(0, 10) : 0.0;

  // The circle on the table.
  const JsonView ref = c["reference"];
  ref.onlyKeys({"centre", "radius", "frequency", "start", "ramp"});
  auto& circle = s.circle;
  if (!ref["centre"].raw().is_array() || ref["centre"].raw().size() != 2) ref["centre"].fail("expected the circle's centre [x, y] in metres");
  circle.centre = {ref["centre"].at(0).inRange(-kMaxLength, kMaxLength), ref["centre"].at(1).inRange(-kMaxLength, kMaxLength)};
  circle.radius = ref["radius"].positive(1.0);
  circle.frequency = ref["frequency"].positive(10.0);
  circle.start = ref["start"].inRange(0, 1e4);
  circle.ramp = ref["ramp"].inRange(0, 1e4);
  // The table must be within the arm's reach under the circle's centre, and the whole circle inside.
  const Eigen::Vector3d centre(circle.centre.x(), circle.centre.y(), p.table_height);
  if (std::abs(p.table_height + p.tip_radius - p.links[0].length) >= p.links[1].length + p.links[2].length)
    tb["height"].fail("expected a table the arm can reach: z_t = " + fmt("%.3g", p.table_height) + " m is out of reach of the shoulder at " +
                      fmt("%.3g", p.links[0].length) + " m (reach " + fmt("%.3g", p.links[1].length + p.links[2].length) + " m)");
  if (const std::string why = outOfReach(p, centre); !why.empty())
    ref["centre"].fail("expected the circle's centre within the arm's workspace on the table: it " + why);
  for (int k = 0; k < 72; ++k) {
    const double a = 2 * M_PI * k / 72;
    const Eigen::Vector3d pt = centre + circle.radius * Eigen::Vector3d(det::cos(a), det::sin(a), 0);
    if (const std::string why = outOfReach(p, pt); !why.empty())
      ref["radius"].fail("expected a circle inside the arm's workspace: its point at " + fmt("%.0f", 360.0 * k / 72) + "° " + why);
  }

  // The start: above the circle's first point.
  const JsonView init = c["initial"];
  init.onlyKeys({"height", "rates"});
  s.start_height = init["height"].inRange(0, 1.0);
  const Eigen::Vector3d start = centre + Eigen::Vector3d(circle.radius, 0, s.start_height);
  if (const std::string why = outOfReach(p, start); !why.empty()) init["height"].fail("expected a start the arm can reach: the tip there " + why);
  if (init.has("rates")) {
    init["rates"].size(3, 3);
    for (std::size_t i = 0; i < 3; ++i) s.rates0[Eigen::Index(i)] = init["rates"].at(i).inRange(-kMaxRate, kMaxRate);
  }

  const SimulationSettings sim = parseSimulation(c["simulation"]);
  s.step = sim.step;
  s.duration = sim.duration;

  // The controller.
  const JsonView ctl = c["controller"];
  ctl.onlyKeys({"kind", "force_law", "inner_loop", "force_setpoint", "delay", "noise", "seed", "table_height_assumed",
                "approach_speed", "torques"});
  auto& cc = s.controller;
  const std::string kind = ctl["kind"].oneOf({"none", "constant", "accommodation"});
  cc.kind = kind == "none" ? ControllerKind::None : kind == "constant" ? ControllerKind::Constant : ControllerKind::Accommodation;
  cc.law = ctl["force_law"].oneOf({"damper", "spring"}) == "damper" ? ForceLaw::Damper : ForceLaw::Spring;
  cc.inner = ctl.has("inner_loop") && ctl["inner_loop"].oneOf({"pd_gravity", "inverse_dynamics"}) == "inverse_dynamics"
                 ? InnerLoop::InverseDynamics
                 : InnerLoop::PdGravity;
  cc.f_zd = ctl["force_setpoint"].inRange(-kMaxForce, kMaxForce);
  if (!(cc.f_zd < 0)) ctl["force_setpoint"].fail("expected a set point f_zd < 0 (N): the force the pen applies to the table, negative pressing");
  cc.delay = ctl["delay"].inRange(0, 1);
  cc.noise = ctl.has("noise") ? ctl["noise"].inRange(0, kMaxForce) : 0.0;
  cc.seed = ctl.has("seed") ? std::uint64_t(ctl["seed"].integer(0, 1LL << 53)) : 1;
  cc.table_assumed = ctl.has("table_height_assumed") ? ctl["table_height_assumed"].inRange(-kMaxLength, kMaxLength) : p.table_height;
  cc.approach_speed = ctl["approach_speed"].positive(10.0);
  if (cc.kind == ControllerKind::Constant) {
    ctl["torques"].size(3, 3);
    for (std::size_t i = 0; i < 3; ++i) cc.torques[Eigen::Index(i)] = ctl["torques"].at(i).inRange(-kMaxTorque, kMaxTorque);
  }
  const auto g = parseGains(c["gains"], {"kp", "kv", "D_z", "K_z"});
  cc.gains = {g.at("kp"), g.at("kv"), g.at("D_z"), g.at("K_z")};
  const JsonView gains = c["gains"];
  if (!(cc.gains.kp > 0)) gains["kp"].fail("expected a position gain k_p > 0 (N/m): the spring's z_ref is f_zd / k_p below the table");
  if (!(cc.gains.kv >= 0)) gains["kv"].fail("expected a damping gain k_v ≥ 0 (N·s/m)");
  if (!(cc.gains.D_z > 0)) gains["D_z"].fail("expected a damper constant D_z > 0 (N·s/m): ż_des = −(f − f_zd)/D_z");
  if (!(cc.gains.K_z > 0)) gains["K_z"].fail("expected a spring constant K_z > 0 (N/m): z_des = z_ref − (f − f_zd)/K_z");

  if (c.has("metrics")) {
    c["metrics"].onlyKeys({"overshoot_window", "max_liftoffs"});
    s.overshoot_window = c["metrics"]["overshoot_window"].positive(1e3);
    if (c["metrics"].has("max_liftoffs")) s.max_liftoffs = int(c["metrics"]["max_liftoffs"].integer(1, 1000000));
  }
  if (c.has("drawing")) {
    c["drawing"].onlyKeys({"arrow_scale"});
    s.arrow_scale = c["drawing"]["arrow_scale"].positive(1e3);
  }
  return s;
}

PenOnTableLab::PenOnTableLab(Settings s) : SettingsLab(std::move(s)) {
  columns_ = kColumns;
  units_ = {
      {"t", "s"},      {"q1", "rad"},   {"q2", "rad"},   {"q3", "rad"},     {"tau1", "N·m"},  {"tau2", "N·m"},
      {"tau3", "N·m"}, {"x_p", "m"},    {"y_p", "m"},    {"z_p", "m"},      {"x_d", "m"},     {"y_d", "m"},
      {"z_des", "m"},  {"f_z", "N"},    {"f_zd", "N"},   {"f_meas", "N"},   {"contact", "1"}, {"gap", "m"},
      {"energy", "J"}, {"work", "J"},   {"constraint_residual", "m"}, {"f_z_5ms", "N"}};
  agreement_units_ = {
      {"max_dq", "rad"},          {"max_dp", "m"},           {"touchdown_hand", "s"}, {"touchdown_bullet", "s"}, {"d_touchdown", "s"},
      {"max_df_settled", "N"},    {"mean_df_settled", "N"},  {"contact_mismatch_time", "s"}};
  // Passive (τ = 0) under gravity the arm falls onto the table, and the plastic touchdown takes energy by
  // design; the check's patch takes gravity out and sets the arm turning about the column instead: a free
  // spatial arm, off the table, whose energy RK4 + projection keeps (tests/labs/pen_on_table_test.cpp).
  passive_ = {1e-9, 0.0, {{"mechanism", {{"gravity", 0.0}}}, {"initial", {{"rates", {0.6, -0.2, 0.1}}}}}};
}

void PenOnTableLab::initialState(VecN& q, VecN& v) const {
  const Eigen::Vector3d start(s_.circle.centre.x() + s_.circle.radius, s_.circle.centre.y(), s_.params.table_height + s_.start_height);
  Eigen::Vector3d th;
  inverseKinematics(s_.params, start, th);  // parseSettings checked the start is reachable
  q = th;
  v = s_.rates0;
}

std::unique_ptr<Simulation> PenOnTableLab::simulate(Engine engine) const {
  auto mech = std::make_unique<Mechanism>(s_.params);
  VecN q, v;
  initialState(q, v);
  const double z0 = mech->tip(q).z();
  // A pen that starts on a rigid table starts in contact (its gap is 0 up to rounding, either sign).
  if (s_.start_height == 0 && s_.params.table_stiffness == 0) mech->setClosed(0, true);
  auto hooks = std::make_unique<Hooks>(s_, z0, engine == Engine::Hand ? mech.get() : nullptr);
  return simulateMechanism(engine, std::move(mech), s_.step, q, v, std::move(hooks), kColumns, s_.duration);
}

MujocoTwin PenOnTableLab::mujocoTwin() const {
  MujocoTwin t;
  t.file = "mujoco.xml";
  t.stands_in = "the pen tip on the table as MuJoCo's frictionless geom contact (soft); the arm falls onto it";
  t.contacts = true;
  initialState(t.q, t.v);
  t.dynamics = handDynamics(describe(s_.params));
  return t;
}

json PenOnTableLab::metrics(const Trace& tr) const {
  const std::size_t n = tr.rows();
  const double dt = s_.step.dt, f_zd = s_.controller.f_zd, t_draw = drawingStart();
  const double t_end = n ? tr.at(n - 1, "t") : 0.0;
  // Touchdown: the first row in contact (none: the run's end, and every force metric counts from the start).
  std::size_t first = n;
  for (std::size_t r = 0; r < n && first == n; ++r)
    if (tr.at(r, "contact") > 0.5) first = r;
  const double touchdown = first < n ? tr.at(first, "t") : t_end;
  // The force graded is f_z_5ms, the 5 ms mean (an impact's impulse P reads P / 5 ms): the overshoot
  // from touchdown on, the RMS once the touchdown's own window has passed.
  std::vector<double> ef, ef_draw, ep;
  double overshoot = 0, lost = 0, pull = -INFINITY, tau = 0, drift = 0, residual = 0, radius = 0, gap_min = INFINITY, ss = 0;
  std::size_t drawn = 0, ss_rows = 0;
  int liftoffs = 0;
  Liftoffs lifts{s_.overshoot_window};
  const double e0 = n ? tr.at(0, "energy") : 0.0;
  for (std::size_t r = 0; r < n; ++r) {
    const double t = tr.at(r, "t"), e = tr.at(r, "f_z_5ms") - f_zd;
    const bool contact = tr.at(r, "contact") > 0.5;
    if (first == n || (r >= first && t >= touchdown + kImpactWindow - 1e-9)) ef.push_back(e);
    if (r >= first && t <= touchdown + s_.overshoot_window) overshoot = std::max(overshoot, -e);
    if (r >= first && !contact) lost += dt;
    if (r > first && r < n && !contact && tr.at(r - 1, "contact") > 0.5) ++liftoffs;
    lifts.step(t, contact);
    if (contact) pull = std::max(pull, tr.at(r, "f_z"));
    if (t >= t_end - 1.0) ss += e, ++ss_rows;
    if (t >= t_draw) {
      ef_draw.push_back(e);
      const Eigen::Vector2d p(tr.at(r, "x_p"), tr.at(r, "y_p")), d(tr.at(r, "x_d"), tr.at(r, "y_d"));
      ep.push_back((p - d).norm());
      radius += (p - s_.circle.centre).norm(), ++drawn;
    }
    for (const char* c : {"tau1", "tau2", "tau3"}) tau = std::max(tau, std::abs(tr.at(r, c)));
    drift = std::max(drift, std::abs(tr.at(r, "energy") - e0 - tr.at(r, "work")));
    residual = std::max(residual, tr.at(r, "constraint_residual"));
    gap_min = std::min(gap_min, tr.at(r, "gap"));
  }
  radius = drawn ? radius / double(drawn) : 0.0;
  return {{"touchdown_time", touchdown},
          {"f_rms", ef.empty() ? std::abs(f_zd) : rms(ef)},
          {"f_rms_drawing", ef_draw.empty() ? std::abs(f_zd) : rms(ef_draw)},
          {"f_overshoot", overshoot},
          {"f_ss_error", ss_rows ? ss / double(ss_rows) : 0.0},
          {"contact_lost_time", lost},
          {"liftoffs", liftoffs},
          {"liftoffs_touchdown", lifts.on_touchdown},
          {"liftoffs_pressed", lifts.pressed},
          {"f_pull_max", std::isfinite(pull) ? pull : 0.0},
          {"radius", radius},
          {"radius_error", drawn ? std::abs(radius - s_.circle.radius) : s_.circle.radius},
          {"track_rms", ep.empty() ? 0.0 : rms(ep)},
          {"tau_max", tau},
          {"gap_min", n ? gap_min : 0.0},
          {"energy_drift", drift},
          {"energy_initial", e0},
          {"max_constraint_residual", residual},
          {"steps", tr.steps()}};
}

json PenOnTableLab::differences(const Trace& a, const Trace& b, std::size_t n) const {
  const auto touchdown = [](const Trace& tr, std::size_t rows) {
    for (std::size_t r = 0; r < rows; ++r)
      if (tr.at(r, "contact") > 0.5) return tr.at(r, "t");
    return rows ? tr.at(rows - 1, "t") : 0.0;
  };
  const double ta = touchdown(a, n), tb = touchdown(b, n), settled = std::max(ta, tb) + s_.overshoot_window;
  double dq = 0, dp = 0, df = 0, df_sum = 0, mismatch = 0;
  std::size_t compared = 0;
  for (std::size_t r = 0; r < n; ++r) {
    for (const char* c : {"q1", "q2", "q3"}) dq = std::max(dq, std::abs(a.at(r, c) - b.at(r, c)));
    dp = std::max(dp, Eigen::Vector3d(a.at(r, "x_p") - b.at(r, "x_p"), a.at(r, "y_p") - b.at(r, "y_p"), a.at(r, "z_p") - b.at(r, "z_p")).norm());
    const bool ca = a.at(r, "contact") > 0.5, cb = b.at(r, "contact") > 0.5;
    if (ca != cb) mismatch += s_.step.dt;
    // The force once both have touched down and settled: the touchdown impulse itself is excluded
    // (the hand model takes it as a velocity jump, Bullet spreads it over two steps).
    if (a.at(r, "t") >= settled && ca && cb) {
      const double d = std::abs(a.at(r, "f_z") - b.at(r, "f_z"));
      df = std::max(df, d), df_sum += d, ++compared;
    }
  }
  return {{"max_dq", dq},
          {"max_dp", dp},
          {"touchdown_hand", ta},
          {"touchdown_bullet", tb},
          {"d_touchdown", std::abs(ta - tb)},
          {"max_df_settled", df},
          {"mean_df_settled", compared ? df_sum / double(compared) : 0.0},
          {"contact_mismatch_time", mismatch}};
}

DYNLAB_REGISTER_LAB(pen_on_table, "Pen on table: draw a circle while pressing with a set force (position accommodation, a unilateral contact)",
                    labFactory<PenOnTableLab>(parseSettings));

}  // namespace dyn::pen_on_table
