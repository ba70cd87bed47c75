// Impedance lab: parses impedance.json, runs the motion-control arm (its mechanism description,
// reused) on the hand-written model or on Bullet, with the tip force an external force of the
// description (physics/forces.h push: each engine evaluates J_tipᵀ F_ext inside its step, at every RK4
// stage for the hand engine, while the controller's τ is held over its period) and the wall as a
// planar PlaneContact, and measures the runs.
#include "labs/impedance/lab.h"

#include <cmath>
#include <functional>
#include <random>

#include "labs/controllers/laws.h"
#include "labs/delay_line.h"
#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "labs/settings.h"
#include "physics/constraints/plane_contact.h"
#include "physics/det/det.h"
#include "physics/det/normal.h"
#include "physics/forces.h"

namespace dyn::impedance {
namespace {

using motion_control::Params;
constexpr double kMaxLength = 100, kMaxMass = 1e6, kMaxForce = 1e5;
// The hand engine's RK4 step in kSwingSubsteps sub-steps while a joint turns faster than kSwing
// (motion_control::RefinedArm): the passive arm under gravity whips at up to 21 rad/s, where a 1 ms step
// is 1.5e-6 m off the reference; the pushes and the controlled arm are far slower and keep one step.
constexpr double kSwing = 8.0;  // rad/s
constexpr int kSwingSubsteps = 2;

Eigen::Vector3d parse3(const JsonView& j, double lo, double hi, double scale = 1.0) {
  j.size(3, 3);
  return {j.at(0).inRange(lo, hi) * scale, j.at(1).inRange(lo, hi) * scale, j.at(2).inRange(lo, hi) * scale};
}

// The arm with the push on the tip (an external force, if any) and the wall (if any) as a unilateral
// plane contact on the tip ball.
MechanismModel<Planar> describeWithWall(const Settings& s) {
  MechanismModel<Planar> d = motion_control::describe(s.plant);
  const Planar::Pos tip(s.plant.links[2].length, 0.0);
  if (s.force.value != Eigen::Vector2d::Zero())
    d.forces.push_back(std::make_shared<PushForce<Planar>>(BodyRef::link(2), tip, Planar::Vec(0.0, s.force.value.x(), s.force.value.y()),
                                                            s.force.profile()));
  if (!s.wall.enabled) return d;
  PlaneContactParams c;
  c.radius = s.wall.radius;
  c.height = -s.wall.x;  // outward normal −x̂: n·x = −x_wall
  c.stiffness = s.wall.stiffness;
  c.damping = s.wall.damping;
  d.constraints.push_back(std::make_shared<PlaneContact<Planar>>(BodyRef::link(2), Planar::Pos(s.plant.links[2].length, 0.0),
                                                                 Planar::Pos(-1.0, 0.0), c));
  return d;
}

// The task Jacobian rows (x, y, φ) and J'θ' from the mechanism's point Jacobian rows (ω, vx, vy).
template <class Mech>
void taskJacobian(Mech& m, const Params& p, const VecN& q, const VecN& v, Eigen::Matrix3d& J, Eigen::Vector3d& Jdv) {
  MatN J3;
  VecN jd;
  m.pointJacobian(2, Planar::Pos(p.links[2].length, 0.0), q, v, J3, jd);
  J.row(0) = J3.row(1), J.row(1) = J3.row(2), J.row(2) = J3.row(0);
  Jdv << jd[1], jd[2], jd[0];
}

// The lab's controller: the chosen realisation of the target impedance on measured F.
class Hooks final : public StepHooks {
 public:
  // The x impulse (N·s) the hand engine's last step gave the tip at a rigid wall (unset: none).
  std::function<double()> impulse;
  explicit Hooks(const Settings& s)
      : s_(s), model_(motion_control::describeRigid(s.model)), plant_(motion_control::describeRigid(s.plant)),
        inner_(s.inner, s.model), hold_(std::max(1L, std::lround(s.period / s.step.dt))), rng_(12345),
        fx_(s.delay, s.step.dt), fy_(s.delay, s.step.dt) {
    x_ref_ = tipPose(s.plant, s.pose);
    x_des_ = x_ref_, v_des_.setZero(), a_des_.setZero();
    tau_ = Eigen::Vector3d::Zero();
  }
  VecN torque(double t, const VecN& q, const VecN& v) override {
    // The controller, sampled; the push at the tip is the mechanism's (describeWithWall), here only for
    // the trace row and the sensor.
    f_applied_ = s_.force.at(t);
    if (k_++ % hold_ == 0) tau_ = control(t, q, v);
    return VecN(tau_);
  }
  void row(const StepRecord& r, std::vector<double>& out) override {
    const Eigen::Vector3d x = tipPose(s_.plant, r.q.head<3>());
    Eigen::Vector2d f = f_applied_;
    // The wall's push on the tip (plane on body: the constraint's force is body on world).
    if (s_.wall.enabled && !r.forces.empty() && r.forces[0].size() >= 3) f += Eigen::Vector2d(r.forces[0][1], r.forces[0][2]);
    // A rigid wall's plastic impact: the hand engine jumps θ' at the touchdown it locates inside the
    // step (eq. (2) for impulses), and the contact force it reports at the step's start leaves the
    // impulse out; the row carries it as P/dt, the step's mean force, as Bullet's impulse-based contact
    // reports it (the engine's own record: ConstrainedMechanism::impactImpulse).
    if (impulse && r.engine == Engine::Hand) f.x() += impulse() / s_.step.dt;
    f_total_ = f;
    out.clear();
    out.push_back(r.t);
    for (int i = 0; i < 3; ++i) out.push_back(r.q[i]);
    for (int i = 0; i < 3; ++i) out.push_back(tau_[i]);
    for (int i = 0; i < 3; ++i) out.push_back(x[i]);
    for (int i = 0; i < 3; ++i) out.push_back(x_ref_[i]);
    out.push_back(x_des_[0]);
    out.push_back(x_des_[1]);
    out.push_back(f[0]);
    out.push_back(f[1]);
    out.push_back(r.energy);
    out.push_back(r.work);
    // The target's analytic response to the push (a step on, a step off): x_ref + K⁻¹F (on − off).
    const Force& push = s_.force;
    const double t_on = push.start + push.rise / 2, t_off = push.hold > 0 ? t_on + push.rise / 2 + push.hold : 1e300;
    for (int a = 0; a < 2; ++a) {
      const double w = std::sqrt(s_.target.K[a] / s_.target.M[a]), z = s_.target.D[a] / (2 * std::sqrt(s_.target.K[a] * s_.target.M[a]));
      out.push_back(x_ref_[a] + push.value[a] / s_.target.K[a] * (unitStep(w, z, r.t - t_on) - unitStep(w, z, r.t - t_off)));
    }
    // The target spring's force at the hand, K_des,x (x − x_ref): against x, the line of slope K_des.
    out.push_back(s_.target.K[0] * (x[0] - x_ref_[0]));
  }
  void observe(const StepRecord& r) override {
    (void)r;
    // The force sensor: what it reads now arrives `delay` later, with noise.
    det::Normal n;  // Marsaglia polar over rng_ (physics/det/normal.h)
    const double nx = s_.noise > 0 ? s_.noise * n(rng_) : 0, ny = s_.noise > 0 ? s_.noise * n(rng_) : 0;
    fx_.push(f_total_[0] + nx), fy_.push(f_total_[1] + ny);
  }

 private:
  Eigen::Vector3d control(double t, const VecN& q, const VecN& v) {
    namespace laws = controllers::laws;
    const Eigen::Vector3d th = q.head<3>(), thd = v.head<3>();
    const Eigen::Vector3d F(fx_.value(), fy_.value(), 0.0);
    const Target& T = s_.law;
    Eigen::Vector3d tau = Eigen::Vector3d::Zero();
    switch (s_.kind) {
      case Kind::None: break;
      case Kind::Constant: tau = s_.constant; break;
      case Kind::TaskSpace: {
        // τ = Ĝ + Jᵀ(K_des e + D_des ė), e = x_ref − x: the arm keeps its own Λ(q).
        Eigen::Matrix3d J;
        Eigen::Vector3d Jdv;
        taskJacobian(model_, s_.model, q, v, J, Jdv);
        const Eigen::Vector3d e = x_ref_ - tipPose(s_.model, th), ed = -J * thd;
        tau = laws::taskPdGravity(Eigen::Vector3d(model_.gravityTorque(VecN(th))), J, T.K, e, T.D, ed);
        break;
      }
      case Kind::FeedbackLinearisation: {
        // ẍ* = M_des⁻¹(F − D_des ẋ − K_des (x − x_ref)); θ'' = J⁻¹(ẍ* − J'θ'); τ = M̂θ'' + ĥ − Jᵀ F.
        Eigen::Matrix3d J;
        Eigen::Vector3d Jdv;
        taskJacobian(model_, s_.model, q, v, J, Jdv);
        const Eigen::Vector3d x = tipPose(s_.model, th), xd = J * thd;
        const Eigen::Vector3d a = laws::impedanceAcceleration(F, T.M, T.D, T.K, x, xd, x_ref_);
        const Eigen::Vector3d qdd = J.partialPivLu().solve(a - Jdv);
        tau = model_.inverseDynamics(VecN(th), VecN(thd), VecN(qdd)) - J.transpose() * F;
        break;
      }
      case Kind::JointSpace: {
        // The impedance model on measured F gives x_des, v_des, a_des (semi-implicit Euler over the
        // control period); inverse kinematics gives θ_des, θ_des', θ_des''; the motion-control lab's
        // joint controller (pid, computed_torque or pd_gravity) tracks them.
        const double h = s_.period;
        a_des_ = laws::impedanceAcceleration(F, T.M, T.D, T.K, x_des_, v_des_, x_ref_);
        v_des_ += h * a_des_;
        x_des_ += h * v_des_;
        Eigen::Vector3d thd_des = th;
        if (!inverseKinematics(s_.model, x_des_, th, thd_des)) thd_des = th;
        Eigen::Matrix3d Jd;
        Eigen::Vector3d Jdv;
        const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
        taskJacobian(model_, s_.model, VecN(thd_des), VecN(zero), Jd, Jdv);
        const Eigen::Vector3d w_des = Jd.partialPivLu().solve(v_des_);
        taskJacobian(model_, s_.model, VecN(thd_des), VecN(w_des), Jd, Jdv);
        const Eigen::Vector3d al_des = Jd.partialPivLu().solve(a_des_ - Jdv);
        const motion_control::Reference ref{thd_des, w_des, al_des};
        tau = inner_.torque(t, th, thd, ref);
        break;
      }
    }
    laws::saturate(tau, s_.tau_max);
    return tau;
  }

  const Settings& s_;
  motion_control::FixedArm<3> model_, plant_;  // fixed sizes: the controller's kinematics unrolled
  motion_control::Controller inner_;
  long hold_, k_ = 0;
  std::mt19937 rng_;
  DelayLine fx_, fy_;
  Eigen::Vector3d tau_, x_ref_, x_des_, v_des_, a_des_;
  Eigen::Vector2d f_applied_ = Eigen::Vector2d::Zero(), f_total_ = Eigen::Vector2d::Zero();
};

}  // namespace

Eigen::Vector2d Force::at(double t) const { return profile().at(t) * value; }

Eigen::Vector3d tipPose(const Params& p, const Eigen::Vector3d& th) {
  const auto pts = motion_control::jointPoints(p, th);
  return {pts.back().x(), pts.back().y(), th.sum()};
}

bool inverseKinematics(const Params& p, const Eigen::Vector3d& x, const Eigen::Vector3d& like, Eigen::Vector3d& th) {
  const double l1 = p.links[0].length, l2 = p.links[1].length, l3 = p.links[2].length;
  const Eigen::Vector2d w(x[0] - l3 * det::cos(x[2]), x[1] - l3 * det::sin(x[2]));
  const double c2 = (w.squaredNorm() - l1 * l1 - l2 * l2) / (2 * l1 * l2);
  if (!(std::abs(c2) <= 1)) return false;
  const double s2 = (like[1] >= 0 ? 1 : -1) * std::sqrt(1 - c2 * c2);
  th[1] = det::atan2(s2, c2);
  th[0] = det::atan2(w.y(), w.x()) - det::atan2(l2 * s2, l1 + l2 * c2);
  th[2] = x[2] - th[0] - th[1];
  // Keep the angles on the branch nearest `like` (continuity across ±π).
  for (int i = 0; i < 3; i += 2) th[i] += 2 * M_PI * std::round((like[i] - th[i]) / (2 * M_PI));
  return true;
}

Settings parseSettings(const JsonView& c) {
  Settings s;
  c.onlyKeys({"lab", "title", "description", "variants", "mechanism", "model", "pose_deg", "environment", "simulation", "controller",
              "target", "gains", "metrics", "rubric", "drawing", "submission_options", "metric_docs", "map", "figures"});
  const JsonView m = c["mechanism"];
  m.onlyKeys({"links", "payload", "gravity", "torque_limit"});
  m["links"].size(3, 3);
  for (std::size_t i = 0; i < 3; ++i) {
    const JsonView l = m["links"].at(i);
    l.onlyKeys({"length", "mass", "inertia", "com"});
    l["com"].size(2, 2);
    s.plant.links.push_back({l["length"].positive(kMaxLength), l["mass"].positive(kMaxMass), l["inertia"].positive(kMaxMass),
                             {l["com"].at(0).inRange(-kMaxLength, kMaxLength), l["com"].at(1).inRange(-kMaxLength, kMaxLength)}});
  }
  s.plant.friction.assign(3, {});
  s.plant.payload = m["payload"].inRange(0, kMaxMass);
  m["gravity"].size(2, 2);
  s.plant.gravity = {m["gravity"].at(0).inRange(-1e3, 1e3), m["gravity"].at(1).inRange(-1e3, 1e3)};
  s.tau_max = parse3(m["torque_limit"], 1e-6, kMaxForce);
  s.plant.stiffness.assign(3, 0.0);
  const JsonView md = c["model"];
  md.onlyKeys({"payload"});
  s.model = s.plant;
  s.model.payload = md["payload"].inRange(0, kMaxMass);
  s.pose = parse3(c["pose_deg"], -360, 360, M_PI / 180);
  // The task Jacobian must be square and invertible at the reference pose (away from singularities).
  if (std::abs(det::sin(s.pose[1])) < 1e-3)
    c["pose_deg"].fail("a pose away from the task Jacobian's singularity (elbow angle not 0° or 180°)");

  const JsonView env = c["environment"];
  env.onlyKeys({"force", "wall", "sensor_noise", "sensor_delay"});
  const JsonView f = env["force"];
  f.onlyKeys({"value", "start", "rise", "hold"});
  f["value"].size(2, 2);
  s.force.value = {f["value"].at(0).inRange(-kMaxForce, kMaxForce), f["value"].at(1).inRange(-kMaxForce, kMaxForce)};
  s.force.start = f["start"].inRange(0, 1e4);
  s.force.rise = f["rise"].inRange(0, 1e4);
  s.force.hold = f["hold"].inRange(0, 1e4);
  const JsonView w = env["wall"];
  w.onlyKeys({"enabled", "x", "stiffness", "damping", "radius"});
  s.wall.enabled = w["enabled"].boolean();
  s.wall.x = w["x"].inRange(-kMaxLength, kMaxLength);
  s.wall.stiffness = w["stiffness"].inRange(0, 1e9);
  s.wall.damping = w["damping"].inRange(0, 1e7);
  s.wall.radius = w["radius"].inRange(0, 1);
  s.noise = env["sensor_noise"].inRange(0, kMaxForce);
  s.delay = env["sensor_delay"].inRange(0, 1);

  const SimulationSettings sim = parseSimulation(c["simulation"]);
  s.step = sim.step;
  s.step.refine_substeps = kSwingSubsteps;
  s.duration = sim.duration;
  if (s.wall.enabled && tipPose(s.plant, s.pose)[0] + s.wall.radius > s.wall.x)
    c["environment"]["wall"]["x"].fail("a wall to the right of the tip at the reference pose");

  const JsonView ctl = c["controller"];
  ctl.onlyKeys({"kind", "inner", "joint_scale", "control_period", "constant_torque"});
  const std::string kind = ctl["kind"].oneOf({"none", "constant", "joint_space", "task_space", "feedback_linearisation"});
  s.kind = kind == "none" ? Kind::None : kind == "constant" ? Kind::Constant : kind == "joint_space" ? Kind::JointSpace
           : kind == "task_space" ? Kind::TaskSpace : Kind::FeedbackLinearisation;
  s.period = ctl["control_period"].inRange(s.step.dt, 1.0);
  const double ratio = s.period / s.step.dt;
  if (std::abs(ratio - std::round(ratio)) > 1e-6) ctl["control_period"].fail("expected a whole multiple of /simulation/dt");
  s.constant = ctl.has("constant_torque") ? parse3(ctl["constant_torque"], -kMaxForce, kMaxForce) : Eigen::Vector3d::Zero();

  // The exercise's target along x and y: K and M given, D = 2ζ√(KM); φ is not graded (the law's).
  const JsonView tg = c["target"];
  tg.onlyKeys({"k_xy", "m_xy", "zeta"});
  const double k_t = tg["k_xy"].positive(1e7), m_t = tg["m_xy"].positive(1e4), z_t = tg["zeta"].inRange(0, 100);
  // The controller's impedance per axis (the student's gains): what task_space, feedback
  // linearisation and joint_space's impedance model are programmed with.
  const auto g = parseGains(c["gains"], {"k_xy", "d_xy", "m_xy", "k_phi", "d_phi", "m_phi", "joint_kp", "joint_ki", "joint_kd"});
  for (const char* k : {"k_xy", "k_phi", "m_xy", "m_phi"})
    if (!(g.at(k) > 0)) c["gains"][k].fail(std::string("a positive ") + k + " (the impedance must be positive definite)");
  s.law.K << g.at("k_xy"), g.at("k_xy"), g.at("k_phi");
  s.law.M << g.at("m_xy"), g.at("m_xy"), g.at("m_phi");
  s.law.D << g.at("d_xy"), g.at("d_xy"), g.at("d_phi");
  s.target = s.law;
  s.target.K.head<2>().setConstant(k_t), s.target.M.head<2>().setConstant(m_t);
  s.target.D.head<2>().setConstant(2 * z_t * std::sqrt(k_t * m_t));
  // joint_space's inner loop, the motion-control lab's controller: computed_torque's K_p, K_d act on
  // the error dynamics (1/s², 1/s, every joint alike); pid's and pd_gravity's are torques per error,
  // spread over the joints by joint_scale. Absent (older configs): computed torque, as before.
  motion_control::ControllerConfig& in = s.inner;
  const std::string inner = ctl.has("inner") ? ctl["inner"].oneOf({"pid", "computed_torque", "pd_gravity"}) : "computed_torque";
  in.kind = inner == "pid" ? motion_control::Kind::Pid : inner == "pd_gravity" ? motion_control::Kind::PdGravity
                                                                              : motion_control::Kind::ComputedTorque;
  const Eigen::Vector3d scale = ctl.has("joint_scale") ? parse3(ctl["joint_scale"], 0, 1e3) : Eigen::Vector3d(1.0, 0.5, 0.05);
  const Eigen::Vector3d ones = Eigen::Vector3d::Ones(), per = in.kind == motion_control::Kind::ComputedTorque ? ones : scale;
  in.kp = g.at("joint_kp") * per, in.kd = g.at("joint_kd") * per;
  in.ki = in.kind == motion_control::Kind::Pid ? Eigen::VectorXd(g.at("joint_ki") * scale) : Eigen::VectorXd::Zero(3);
  in.anti_windup = motion_control::AntiWindup::Clamping;
  in.coulomb_compensation = false;  // the arm here has no joint friction
  in.tau_max = s.tau_max;
  in.constant = Eigen::VectorXd::Zero(3);
  in.period = s.period;
  return s;
}

ImpedanceLab::ImpedanceLab(Settings s) : SettingsLab(std::move(s)) {
  columns_ = {"t", "q1", "q2", "q3", "tau1", "tau2", "tau3", "x", "y", "phi", "x_ref", "y_ref", "phi_ref",
              "x_des", "y_des", "F_ext_x", "F_ext_y", "energy", "work", "x_target", "y_target", "F_spring_x"};
  units_ = {
      {"t", "s"}, {"q1", "rad"}, {"q2", "rad"}, {"q3", "rad"}, {"tau1", "N·m"}, {"tau2", "N·m"}, {"tau3", "N·m"},
      {"x", "m"}, {"y", "m"}, {"phi", "rad"}, {"x_ref", "m"}, {"y_ref", "m"}, {"phi_ref", "rad"}, {"x_des", "m"},
      {"y_des", "m"}, {"x_target", "m"}, {"y_target", "m"}, {"F_ext_x", "N"}, {"F_ext_y", "N"}, {"F_spring_x", "N"}, {"energy", "J"}, {"work", "J"}};
  agreement_units_ = {{"max_dx", "m"}, {"max_dtau", "N·m"}};
  // Passive with no push and no wall the arm falls from the reference pose and whips through fast
  // swings (E0 ≈ 16 J): RK4 at 1 ms keeps E within 1e-5·|E0| over 1 s (measured 3e-6).
  passive_ = {1e-5, 1.0, {{"environment", {{"force", {{"value", {0.0, 0.0}}}}, {"wall", {{"enabled", false}}}}}}};
}

namespace {

// A run on mechanism type M (its sizes fixed: every loop of the step unrolled).
template <class M>
std::unique_ptr<Simulation> run(const Settings& s, Engine engine, const std::vector<std::string>& columns) {
  auto mech = std::make_unique<motion_control::RefinedArm<M>>(describeWithWall(s));
  mech->swing = kSwing;
  VecN q = VecN(s.pose), v = VecN::Zero(3);
  auto hooks = std::make_unique<Hooks>(s);
  if (engine == Engine::Hand && s.wall.enabled && s.wall.stiffness == 0)
    hooks->impulse = [hand = mech.get()] { return hand->impactImpulse(0)[1]; };  // (τ, f_x, f_y): f_x
  return simulateMechanism(engine, std::move(mech), s.step, q, v, std::move(hooks), columns, s.duration);
}

}  // namespace

// The arm alone: 3 joints, no rows; with the wall: 3 joints, its one contact row (mechanism.cpp).
std::unique_ptr<Simulation> ImpedanceLab::simulate(Engine engine) const {
  if (s_.wall.enabled) return run<WallArm>(s_, engine, columns_);
  return run<motion_control::FixedArm<3>>(s_, engine, columns_);
}

MujocoTwin ImpedanceLab::mujocoTwin() const {
  MujocoTwin t;
  t.file = "mujoco.xml";
  t.stands_in = "the arm passive (no push; the wall's contact off, as dynlab runs MuJoCo)";
  t.q = VecN(s_.pose), t.v = VecN::Zero(3);
  t.dynamics = handDynamics(motion_control::describe(s_.plant));
  return t;
}

DYNLAB_REGISTER_LAB(impedance, "Impedance control: make the hand feel like a given mass-spring-damper, three ways",
                    labFactory<ImpedanceLab>(parseSettings));

}  // namespace dyn::impedance
