// The motion-control lab (labs/motion_control) against the lecture's §4 claims, cheap runs only:
//  * τ = 0 without friction conserves energy to 1e-6 J in 1 s (RK4), rigid and flexible (springs included);
//  * with friction and a controller, E − E0 equals the work of τ plus the friction's (the RK4 books);
//  * with Coulomb friction (F_c tanh(θ'/w)) the PID run converges at fourth order (dt 0.25 → 0.125 ms; the clamp: second);
//  * a passive flexible arm at the lab's default step (sub-stepped: ω dt ≤ 0.04) agrees with dt/4 to 1e-6 rad over 3 s;
//  * computed torque with an exact model (friction included): e(t) = (e0 + (e0' + ω e0) t) e^{−ωt}
//    for ζ = 1, within 1e-3·|e0| at dt = 0.2 ms (the 1-step zero-order hold costs O(ω dt));
//  * PD + gravity, set-point: V = ½θ'ᵀMθ' + ½eᵀK_p e never rises by more than 1e-9·V0 a step and the arm settles;
//  * flexible joints: the static deflection of the outstretched arm equals (the moment of gravity
//    outboard of joint i)/k_i, by hand;
//  * anti-windup: clamping keeps |u_I| ≤ τ_max, back-calculation within (k_P + k_I T_t)e of it, none grows;
//  * hand vs Bullet over 1 s of PID tracking: |Δθ| ≤ 5 mrad (Bullet's first-order step at dt = 1 ms);
//  * the fixed–free spring chain (lecture §1): small-oscillation frequencies from eig(M⁻¹K) equal
//    2√(k/J) sin((2j−1)π/(2(2N+1))) (equal J, k) to 1e-10, and the simulated chain released in its
//    first mode swings at ω_1 (one period within 1e-4 relative);
//  * the reference hook (torque(t, θ, θ', reference)) equals the trajectory form exactly;
//  * bad inputs get one line naming the JSON path.
//  * flexible screening (linearise.cpp): one flexible joint's twist after a fast 3° move rings at the
//    screened least damped mode's frequency within 2 % (0.5 % measured; pid, computed torque, PD + gravity);
//    with springs 10⁴× stiffer the loops' poles lie within 1e-3 of the rigid screening's (rotors turned
//    with their links), ~1/k; the feedback names the mode and warns exactly when ζ < kLightDamping.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "grading/scenario.h"
#include "labs/motion_control/lab.h"
#include "labs/motion_control/linearise.h"
#include "labs/run.h"
#include "tests/labs/lab_fixture.h"

using namespace dyn;
using namespace dyn::motion_control;

namespace {

const test::LabFixture fixture("motion_control");

Settings settings(const json& patch) {
  const json c = fixture.config(patch);
  return parseSettings(JsonView(c, fixture.file));
}

json noFriction() {
  json zero = json::array();
  for (int i = 0; i < 3; ++i) zero.push_back({{"viscous", 0.0}, {"coulomb", 0.0}});
  return zero;
}

// Runs the plant under a controller from θ0 with θ_d held at `target`; calls f(t, θ, θ', V) each step.
template <class F>
void setPoint(Settings s, const Eigen::VectorXd& theta0, const Eigen::VectorXd& target, double dt, double duration, F f) {
  s.trajectory.outstretched = s.trajectory.folded = target;
  s.trajectory.amplitude.setZero();
  s.controller.period = dt;
  s.step.dt = dt;
  Controller ctrl(s.controller, s.trajectory, s.model);
  ArmMechanism mech(describe(s.plant));
  VecN q, v;
  treeState(s.plant, theta0, Eigen::VectorXd::Zero(theta0.size()), q, v);
  for (long k = 0; k * dt < duration; ++k) {
    const ArmState a = armState(s.plant, q, v);
    const Eigen::VectorXd tau = ctrl.torque(double(k) * dt, a.motor, a.motor_rate);
    f(double(k) * dt, a.link, a.link_rate, ctrl.lyapunov(a.motor - target, a.motor, a.motor_rate));
    REQUIRE(dyn::step(mech, s.step, treeTorque(s.plant, tau), q, v));
  }
}

// A flexible-joint config: springs on, no Coulomb friction (plant and model: the screening leaves it
// out), a fast control period, and this controller.
json flexiblePatch(const char* kind, double stiffness_scale = 1.0) {
  const json flex = fixture.defaults()["mechanism"]["flexible"];
  json k = json::array();
  for (const auto& ki : flex["stiffness"]) k.push_back(ki.get<double>() * stiffness_scale);
  json friction = fixture.defaults()["mechanism"]["friction"];
  for (auto& f : friction) f["coulomb"] = 0.0;
  return {{"mechanism", {{"flexible", {{"enabled", true}, {"stiffness", k}}}, {"friction", friction}}},
          {"model", {{"friction", friction}}},
          {"controller", {{"kind", kind}, {"control_period", 2e-4}}},
          {"simulation", {{"dt", 2e-4}}}};
}

// The screening's loop named `name`, analysed.
LoopAnalysis screened(const Lab& lab, const std::string& name) {
  for (const LinearLoop& l : lab.linearise())
    if (l.name == name) return analyseLoop(l);
  FAIL("no loop " << name);
  return {};
}

// The damped frequency a signal rings at over [from, to]: successive extrema of a damped sine (on an
// offset) lie π/ω_d apart; each extremum is placed by the parabola through its three samples.
double ringFrequency(const Trace& tr, const std::string& column, double from, double to) {
  const std::vector<double> x = tr.series(column), t = tr.series("t");
  // Only the ring counts: the swings about the settled value until they fall below 1 % of the largest.
  const double settled = x.back();
  double amplitude = 0;
  for (std::size_t k = 0; k < x.size(); ++k)
    if (t[k] >= from && t[k] <= to) amplitude = std::max(amplitude, std::abs(x[k] - settled));
  std::vector<double> extrema;
  for (std::size_t k = 1; k + 1 < x.size(); ++k) {
    if (t[k] < from || t[k] > to || (x[k] - x[k - 1]) * (x[k + 1] - x[k]) >= 0) continue;
    if (std::abs(x[k] - settled) < 1e-2 * amplitude) break;  // the ring has died out: slower modes follow
    const double curvature = x[k - 1] - 2 * x[k] + x[k + 1];
    extrema.push_back(t[k] + 0.5 * (t[k + 1] - t[k]) * (x[k - 1] - x[k + 1]) / curvature);
  }
  REQUIRE(extrema.size() >= 4);
  return M_PI * double(extrema.size() - 1) / (extrema.back() - extrema.front());
}

// The arm a stiff-spring flexible arm becomes: each rotor turns with its link, so link i carries
// rotor i's mass at its origin and its inertia (parallel-axis theorem about the new centre of mass).
json lumpedRotors() {
  const json mech = fixture.defaults()["mechanism"];
  const double m_r = mech["flexible"]["rotor_mass"], J_r = mech["flexible"]["rotor_inertia"];
  json links = mech["links"];
  for (auto& l : links) {
    const double m = l["mass"], I = l["inertia"];
    const Eigen::Vector2d c(l["com"][0].get<double>(), l["com"][1].get<double>()), c2 = m * c / (m + m_r);
    l["mass"] = m + m_r;
    l["com"] = {c2.x(), c2.y()};
    l["inertia"] = I + m * (c - c2).squaredNorm() + J_r + m_r * c2.squaredNorm();
  }
  return links;
}

// The largest distance from a pole of `rigid` slower than `slowest` (rad/s) to the nearest pole of
// `flexible`, relative to its size.
double poleGap(const LoopAnalysis& rigid, const LoopAnalysis& flexible, double slowest) {
  double worst = 0;
  for (const auto& p : rigid.poles) {
    if (std::abs(p) > slowest) continue;
    double nearest = 1e300;
    for (const auto& f : flexible.poles) nearest = std::min(nearest, std::abs(f - p));
    worst = std::max(worst, nearest / std::abs(p));
  }
  return worst;
}

}  // namespace

TEST_CASE("motion_control: tau = 0 without friction conserves energy, rigid and flexible") {
  for (bool flexible : {false, true}) {
    CAPTURE(flexible);
    const auto lab = fixture.makeLab({{"controller", {{"kind", "none"}}},
                                      {"mechanism", {{"friction", noFriction()}, {"flexible", {{"enabled", flexible}}}}},
                                      {"simulation", {{"duration", 1.0}, {"dt", flexible ? 2.5e-4 : 1e-3}}}});
    const RunResult r = runEngine(*lab, Engine::Hand);
    REQUIRE(r.failure.empty());
    double worst = 0;
    for (double e : r.trace.series("energy")) worst = std::max(worst, std::abs(e - r.trace.at(0, "energy")));
    MESSAGE("passive, flexible " << flexible << ": max |E − E0| over 1 s " << worst << " J");
    // The falling arm converts ~20 J: 1e-6 J is RK4's error at dt = 1 ms (flexible: the rotor–spring
    // modes near 200 rad/s need dt = 0.25 ms for the same; at 1 ms RK4 loses 7e-4 J in 1 s).
    CHECK(worst < 1e-6);
    CHECK(lab->metrics(r.trace)["energy_initial"].get<double>() == doctest::Approx(r.trace.at(0, "energy")));
  }
}

TEST_CASE("motion_control: with friction, E − E0 = work of τ and of friction") {
  const auto lab = fixture.makeLab({{"simulation", {{"duration", 1.5}}}});
  const RunResult r = runEngine(*lab, Engine::Hand);
  REQUIRE(r.failure.empty());
  const json m = lab->metrics(r.trace);
  double moved = 0;  // |W| at its largest: the scale of the balance
  for (double w : r.trace.series("work")) moved = std::max(moved, std::abs(w));
  CHECK(moved > 1.0);
  // The books integrated with the motion's RK4 stages: the integrator's error, 2e-5 J at dt 1 ms where
  // the tanh friction turns over (fourth order: tests/labs/mechanism_simulation_test.cpp).
  CHECK(m["energy_drift"].get<double>() < 1e-4 * moved);
}

// The largest |Δq| between two hand runs of the same config at steps dt and dt/m, row k against row m k.
double runGap(const json& patch, double dt, int m) {
  auto at = [&](double h) {
    json p = patch;
    p["simulation"]["dt"] = h;
    const auto lab = fixture.makeLab(p);
    const RunResult r = runEngine(*lab, Engine::Hand);
    REQUIRE_MESSAGE(r.failure.empty(), r.failure);
    return r.trace;
  };
  const Trace a = at(dt), b = at(dt / m);
  double gap = 0;
  for (std::size_t r = 0; r < a.rows() && std::size_t(m) * r < b.rows(); ++r)
    for (const char* c : {"q1", "q2", "q3"}) gap = std::max(gap, std::abs(a.at(r, c) - b.at(std::size_t(m) * r, c)));
  return gap;
}

TEST_CASE("motion_control: with Coulomb friction (tanh) the PID run converges at fourth order") {
  // The controller sampled every 2 ms in every run: the same discrete loop, only the plant's step
  // changes. F_c tanh(θ'/w) at w = 0.01 rad/s turns over in w/|θ''| ≈ 1 ms where a joint reverses:
  // RK4 resolves it from dt 0.5 ms on (at 1 ms the gap to dt/2 is 7e-5 rad, ratio 7; at 0.5 ms 1.1e-5).
  // The clamp's kinks held it at second order once resolved: 2.5e-7 then 6.2e-8 rad here (ratio 4).
  const json patch = {{"controller", {{"control_period", 2e-3}}}, {"simulation", {{"duration", 1.0}}}};
  const double coarse = runGap(patch, 2.5e-4, 2), fine = runGap(patch, 1.25e-4, 2);
  MESSAGE("|q(dt) − q(dt/2)| at dt 0.25 ms: " << coarse << " rad, 0.125 ms: " << fine << " rad, ratio " << coarse / fine);
  CHECK(fine < 1e-7);
  CHECK(coarse / fine > 12.0);  // fourth order (16) or better
}

TEST_CASE("motion_control: a passive flexible arm at the lab's default step agrees with dt/4 to 1e-6 rad over 3 s") {
  // Coulomb friction off (viscous kept): the rotor–spring modes are what the sub-steps resolve; the
  // friction's own resolution is the test above.
  json friction = fixture.defaults()["mechanism"]["friction"];
  for (auto& f : friction) f["coulomb"] = 0.0;
  const json patch = {{"controller", {{"kind", "none"}}},
                      {"mechanism", {{"flexible", {{"enabled", true}}}, {"friction", friction}}},
                      {"simulation", {{"duration", 3.0}}}};
  const auto lab = fixture.makeLab(patch);
  const auto& s = dynamic_cast<const MotionControlLab&>(*lab).settings();
  const double w = std::max(fastestMode(s.plant, s.trajectory.outstretched), fastestMode(s.plant, s.trajectory.folded));
  MESSAGE("fastest mode " << w << " rad/s, " << s.step.substeps << " sub-steps of dt " << s.step.dt << " s: ω dt = "
                          << w * s.step.dt / s.step.substeps);
  CHECK(w * s.step.dt / s.step.substeps <= kResolvedOmegaDt);
  const double gap = runGap(patch, s.step.dt, 4);
  MESSAGE("|q(dt) − q(dt/4)| over 3 s: " << gap << " rad");
  CHECK(gap < 1e-6);
}

TEST_CASE("motion_control: computed torque with an exact model makes the error dynamics linear") {
  Settings s = settings({{"controller", {{"kind", "computed_torque"}}},
                         {"gains", {{"omega_n", {{"value", 10.0}}}, {"zeta", {{"value", 1.0}}}}},
                         {"mechanism", {{"torque_limit", {1e4, 1e4, 1e4}}}}});
  s.model = s.plant;  // exact: payload and friction known
  const double w = 10.0;
  const Eigen::Vector3d target(0.5, -1.0, 0.8), e0(0.05, -0.04, 0.03);
  double worst = 0;
  setPoint(s, target + e0, target, 2e-4, 1.0, [&](double t, const Eigen::VectorXd& th, const Eigen::VectorXd&, double) {
    const Eigen::Vector3d expected = (e0 + w * e0 * t) * std::exp(-w * t);
    worst = std::max(worst, (th - target - expected).cwiseAbs().maxCoeff());
  });
  CHECK(worst < 1e-3 * e0.cwiseAbs().maxCoeff());
}

TEST_CASE("motion_control: PD + gravity's V never rises at a set point, and the arm settles") {
  Settings s = settings({{"controller", {{"kind", "pd_gravity"}}},
                         {"gains", {{"kp", {{"value", 400.0}}}, {"kd", {{"value", 20.0}}}}},
                         {"mechanism", {{"torque_limit", {1e4, 1e4, 1e4}}}}});
  for (auto& f : s.plant.friction) f.coulomb = 0;  // Coulomb would leave an offset of F_c/K_p
  s.model = s.plant;
  const Eigen::Vector3d target(0.6, -1.2, 0.9);
  double V0 = -1, rise = 0, prev = 0;
  Eigen::VectorXd last;
  setPoint(s, Eigen::Vector3d::Zero(), target, 5e-4, 3.0, [&](double, const Eigen::VectorXd& th, const Eigen::VectorXd&, double V) {
    if (V0 < 0) V0 = V;
    else rise = std::max(rise, V - prev);
    prev = V;
    last = th;
  });
  CHECK(V0 > 1.0);
  CHECK(rise <= 1e-9 * V0);
  CHECK((last - target).cwiseAbs().maxCoeff() < 1e-3);
}

TEST_CASE("motion_control: a flexible arm's static deflection is the outboard gravity moment over k") {
  const Settings s = settings({{"mechanism", {{"flexible", {{"enabled", true}, {"stiffness", {50.0, 40.0, 10.0}}}}}}});
  const Params& p = s.plant;
  const Eigen::VectorXd th = Eigen::Vector3d(0.3, -0.5, 0.4);
  const Eigen::VectorXd d = staticDeflection(p, th);
  // By hand at the deflected pose: points of the joints and each link's centre of mass (payload at the tip).
  const auto points = jointPoints(p, th);  // θ are the link angles: the deflection is already in them
  double angle = 0;
  std::vector<Eigen::Vector2d> com;
  for (int i = 0; i < 3; ++i) {
    angle += th[i];
    const Eigen::Rotation2Dd R(angle);
    com.push_back(points[std::size_t(i)] + R * p.links[std::size_t(i)].com);
  }
  const double g = -p.gravity.y();
  for (int i = 0; i < 3; ++i) {
    double moment = 0;  // about joint i, of everything it carries (rotors sit on the axes)
    for (int j = i; j < 3; ++j) moment -= p.links[std::size_t(j)].mass * g * (com[std::size_t(j)].x() - points[std::size_t(i)].x());
    for (int j = i + 1; j < 3; ++j) moment -= p.rotor_mass * g * (points[std::size_t(j)].x() - points[std::size_t(i)].x());
    moment -= p.payload * g * (points[3].x() - points[std::size_t(i)].x());
    CHECK(d[i] == doctest::Approx(moment / p.stiffness[std::size_t(i)]).epsilon(1e-9));
  }
}

TEST_CASE("motion_control: anti-windup bounds the integrator under saturation") {
  for (const AntiWindup aw : {AntiWindup::None, AntiWindup::Clamping, AntiWindup::BackCalculation}) {
    Settings s = settings({{"controller", {{"kind", "pid"}}}, {"gains", {{"ki", {{"value", 1000.0}}}}}});
    s.controller.anti_windup = aw;
    s.trajectory.folded = s.trajectory.outstretched;
    s.trajectory.amplitude.setZero();
    Controller c(s.controller, s.trajectory, s.model);
    const Eigen::Vector3d th(1.0, 1.0, 1.0), rate = Eigen::Vector3d::Zero();  // a held error of 1 rad
    double peak = 0;
    for (int k = 0; k < 2000; ++k) {
      c.torque(k * 1e-3, th, rate);
      CHECK(c.saturated());
      peak = std::max(peak, (c.integral().cwiseAbs() - s.controller.tau_max).maxCoeff());
    }
    CAPTURE(int(aw));
    if (aw == AntiWindup::None) CHECK(peak > 100);                        // winds up: k_I·t·e
    if (aw == AntiWindup::Clamping) CHECK(peak <= 0);                     // held within ±τ_max
    // Back-calculation settles where u_I's rate is 0: beyond τ_max by at most (k_P + k_I T_t)·e.
    const double bound = (s.controller.kp + s.controller.ki * s.controller.tracking_time).maxCoeff();
    if (aw == AntiWindup::BackCalculation) CHECK(peak <= bound + 1e-9);
    if (aw == AntiWindup::BackCalculation) CHECK(peak > 0);
  }
}

TEST_CASE("motion_control: the reference hook is the trajectory's law, bit for bit, for every controller") {
  // The same controller fed the trajectory's (θ_d, θ_d', θ_d'') by the caller (the impedance lab's
  // inner loop) gives the same torques and integrator as the one reading its own trajectory.
  for (const char* kind : {"pid", "computed_torque", "pd_gravity"}) {
    const Settings s = settings({{"controller", {{"kind", kind}}}});
    Controller own(s.controller, s.trajectory, s.model), hooked(s.controller, s.model);
    double worst = 0;
    for (int k = 0; k < 3000; ++k) {
      const double t = k * 1e-3;
      const Eigen::Vector3d th(0.1 * std::sin(3 * t), -0.2 * t, 0.05), rate(0.3 * std::cos(3 * t), -0.2, 0.0);
      Reference ref;
      s.trajectory.at(t, ref.q, ref.qd, ref.qdd);
      const Eigen::VectorXd a = own.torque(t, th, rate), b = hooked.torque(t, th, rate, ref);
      worst = std::max({worst, (a - b).cwiseAbs().maxCoeff(), (own.integral() - hooked.integral()).cwiseAbs().maxCoeff()});
    }
    CAPTURE(kind);
    CHECK(worst == 0.0);
  }
  // Without a trajectory the trajectory form says what to call instead.
  const Settings s = settings(json::object());
  Controller hooked(s.controller, s.model);
  CHECK_THROWS_WITH_AS(hooked.torque(0.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()),
                       doctest::Contains("no trajectory"), std::logic_error);
}

TEST_CASE("motion_control: hand and Bullet agree") {
  const auto lab = fixture.makeLab({{"simulation", {{"duration", 1.0}}}});
  const RunResult h = runEngine(*lab, Engine::Hand), b = runEngine(*lab, Engine::Bullet);
  REQUIRE(h.failure.empty());
  REQUIRE(b.failure.empty());
  const json a = lab->agreement(h.trace, b.trace);
  MESSAGE("hand vs Bullet: max |Δθ| = ", a["max_dq"].get<double>(), " rad");
  CHECK(a["max_dq"].get<double>() < 5e-3);
}

TEST_CASE("motion_control: bad inputs get one line naming the path") {
  CHECK(fixture.inputError({{"controller", {{"control_period", 0.0015}}}}) ==
        "/controller/control_period: expected a whole multiple of the simulation step /simulation/dt");
  CHECK(fixture.inputError({{"mechanism", {{"torque_limit", {1.0, 2.0}}}}}).rfind("/mechanism/torque_limit", 0) == 0);
  CHECK(fixture.inputError({{"controller", {{"kind", "lqr"}}}}).rfind("/controller/kind", 0) == 0);
  CHECK(fixture.inputError({{"trajectory", {{"move_time", 0.0}}}}).rfind("/trajectory/move_time", 0) == 0);
  CHECK(fixture.inputError(json::object()) == "accepted");
}

TEST_CASE("motion_control: the fixed-free spring chain's frequencies are eig(M^-1 K) and the closed form") {
  // N coaxial discs (inertia J each, no gravity) on revolute joints with springs k: relative angles in
  // the tree, absolute in the lecture; eig(M⁻¹K) is the same in both (a change of coordinates).
  const int N = 5;
  const double J = 0.02, k = 30.0;
  MechanismModel<Planar> d;
  for (int i = 0; i < N; ++i) {
    d.tree.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(Planar::Pos::Zero()),
                   Planar::inertia(1.0, Eigen::Vector2d::Zero(), J));
    JointProperties spring;
    spring.stiffness = k;
    d.joints.push_back(spring);
  }
  d.tree.gravity.setZero();
  ArmMechanism chain(d);
  const Eigen::MatrixXd M = Eigen::MatrixXd(chain.massMatrix(VecN::Zero(N)));
  const Eigen::MatrixXd K = k * Eigen::MatrixXd::Identity(N, N);
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(K, M);
  for (int j = 1; j <= N; ++j) {
    const double closed = 2 * std::sqrt(k / J) * std::sin((2 * j - 1) * M_PI / (2 * (2 * N + 1)));
    CHECK(std::sqrt(eig.eigenvalues()[j - 1]) == doctest::Approx(closed).epsilon(1e-10));
  }
  // Released at rest in mode 1 (small amplitude), the chain returns to it after one period 2π/ω_1.
  const double w1 = std::sqrt(eig.eigenvalues()[0]);
  const Eigen::VectorXd shape = 0.01 * eig.eigenvectors().col(0);
  VecN q = shape, v = VecN::Zero(N);
  StepOptions o;
  o.dt = 1e-4;
  o.integrator = Integrator::RK4;
  const VecN tau = VecN::Zero(N);
  // Time the first downward zero crossing of the first joint after half a period, then a full period later.
  double t = 0, prev = q[0];
  std::vector<double> crossings;
  while (crossings.size() < 2 && t < 10) {
    REQUIRE(dyn::step(chain, o, tau, q, v));
    t += o.dt;
    if ((prev > 0) != (q[0] > 0)) crossings.push_back(t - o.dt * q[0] / (q[0] - prev));
    prev = q[0];
  }
  REQUIRE(crossings.size() == 2);
  CHECK(2 * (crossings[1] - crossings[0]) == doctest::Approx(2 * M_PI / w1).epsilon(1e-4));
}

TEST_CASE("motion_control: a flexible joint's twist rings at the screened frequency") {
  // One flexible joint (the arm's first link and payload, so "the others held" is exact) makes a
  // fast 3° move and holds; its twist δ rings at the least damped mode of loop j1_out (3° from the
  // outstretched pose, where gravity's gradient vanishes).
  double worst = 0;
  for (const char* kind : {"pid", "computed_torque", "pd_gravity"}) {
    INFO("kind ", kind);
    json patch = flexiblePatch(kind);
    const json one = {1.0};
    const json d = fixture.defaults();
    patch["mechanism"]["links"] = {d["mechanism"]["links"][0]};
    patch["mechanism"]["friction"] = {patch["mechanism"]["friction"][0]};
    patch["model"]["friction"] = patch["mechanism"]["friction"];
    patch["mechanism"]["torque_limit"] = {d["mechanism"]["torque_limit"][0]};
    patch["mechanism"]["flexible"]["stiffness"] = {patch["mechanism"]["flexible"]["stiffness"][0]};
    patch["controller"]["joint_scale"] = one;
    patch["trajectory"] = {{"outstretched_deg", {0.0}}, {"folded_deg", {3.0}}, {"sine_amplitude_deg", {0.0}},
                           {"move_time", 0.05}, {"hold_time", 1.0}};
    patch["simulation"]["duration"] = 1.05;
    const auto lab = fixture.makeLab(patch);
    const Mode mode = leastDampedMode(screened(*lab, "j1_out"));
    REQUIRE(mode.found);
    const double measured = ringFrequency(fixture.run(*lab, Engine::Hand), "defl1", 0.06, 1.05);
    MESSAGE(kind, ": screened ", mode.damped, " rad/s (ζ ", mode.damping, "), simulated ", measured, " rad/s");
    worst = std::max(worst, std::abs(measured / mode.damped - 1));
  }
  // Measured 0.5 % at worst: the ring's first extrema still carry the slower poles' decay, and the
  // run holds 3° from the screened pose. 2 % leaves room for that, not for a wrong mode (the arm's
  // other modes lie 3× away).
  MESSAGE("worst relative gap ", worst);
  CHECK(worst < 0.02);
}

TEST_CASE("motion_control: with very stiff springs the flexible screening tends to the rigid one") {
  // The rigid reference is the arm whose rotors turn with their links (lumpedRotors). pid and
  // pd_gravity do not depend on the model; computed torque's m̂_ii is the rigid model's either way,
  // so its limit is the rigid loop (m̂_ii/(J_m + m_L))(K_d s + K_p)/s².
  for (const char* kind : {"pid", "pd_gravity", "computed_torque"}) {
    INFO("kind ", kind);
    json rigid_patch = flexiblePatch(kind);
    rigid_patch["mechanism"]["flexible"]["enabled"] = false;
    rigid_patch["mechanism"]["links"] = lumpedRotors();
    const auto rigid = fixture.makeLab(rigid_patch);
    std::vector<double> gaps;
    for (const double scale : {1e2, 1e4}) {
      const auto stiff = fixture.makeLab(flexiblePatch(kind, scale));
      const Settings& s = dynamic_cast<const MotionControlLab&>(*stiff).settings();
      double worst = 0;
      for (const LinearLoop& loop : rigid->linearise()) {
        LinearLoop reference = loop;
        if (std::string(kind) == "computed_torque") {
          const bool out = loop.name.find("_out") != std::string::npos;
          const Eigen::VectorXd theta = out ? s.trajectory.outstretched : s.trajectory.folded;
          const int i = loop.name[1] - '1';
          const FlexibleJoint f = flexibleJoint(s.plant, theta, i);
          const double m_hat = ArmMechanism(describeRigid(s.model)).massMatrix(VecN(theta))(i, i);
          const double r = m_hat / (f.rotor + f.link);
          reference.num = {r * s.controller.kp[i], r * s.controller.kd[i]};
          reference.den = {0, 0, 1};
        }
        // The arm's and controller's poles; the delay's Padé poles (~1/T) move with the spring mode.
        worst = std::max(worst, poleGap(analyseLoop(reference), screened(*stiff, loop.name), 0.1 / loop.delay));
      }
      MESSAGE(kind, ": stiffness ×", scale, ": worst relative pole gap ", worst);
      gaps.push_back(worst);
    }
    CHECK(gaps[1] < 1e-3);
    CHECK(gaps[1] < gaps[0] / 30);  // ~1/k: 100× stiffer springs, ~100× closer
  }
}

TEST_CASE("motion_control: the flexible screening names the vibration mode in the feedback") {
  for (const char* kind : {"pid", "computed_torque", "pd_gravity"}) {
    INFO("kind ", kind);
    const auto flexible = fixture.makeLab(flexiblePatch(kind));
    const ScreenResult screen = screenLoops(*flexible);
    const auto loops = flexible->linearise();
    REQUIRE(screen.notes.size() == loops.size());
    for (std::size_t k = 0; k < loops.size(); ++k) {
      INFO(screen.notes[k]);
      const Mode mode = leastDampedMode(analyseLoop(loops[k]));
      REQUIRE(mode.found);
      CHECK(screen.notes[k].find("least damped mode ") != std::string::npos);
      CHECK((screen.notes[k].find("warning") != std::string::npos) == (mode.damping < kLightDamping));
    }
    // Rigid, no remark.
    json rigid = flexiblePatch(kind);
    rigid["mechanism"]["flexible"]["enabled"] = false;
    for (const std::string& note : screenLoops(*fixture.makeLab(rigid)).notes) CHECK(note.find("least damped") == std::string::npos);
  }
}

TEST_CASE("motion_control: the unknown payload stays unknown: PD + gravity settles off by K_p⁻¹ (G − Ĝ)") {
  // The rubric's payload scenario changes the plant only; the model keeps the nominal payload.
  const json scenario = fixture.defaults()["rubric"]["scenarios"]["payload_plus_20"]["patch"];
  CHECK_FALSE(scenario.contains("model"));
  Settings s = settings(mergePatch(scenario, {{"controller", {{"kind", "pd_gravity"}}},
                                              {"gains", {{"kp", {{"value", 2000.0}}}, {"kd", {{"value", 60.0}}}}},
                                              {"mechanism", {{"torque_limit", {1e4, 1e4, 1e4}}}}}));
  CHECK(s.plant.payload > s.model.payload);
  CHECK(s.model.payload == fixture.defaults()["model"]["payload"].get<double>());
  for (auto& f : s.plant.friction) f.coulomb = 0;  // no Coulomb offset at rest
  for (auto& f : s.model.friction) f.coulomb = 0;
  // At rest τ = −K_p e + Ĝ(θ) = G(θ): e = −K_p⁻¹ (G − Ĝ)(θ), solved by fixed point about the target.
  const Eigen::Vector3d target(0.3, -0.6, 0.4);
  ArmMechanism plant(describe(s.plant)), model(describe(s.model));
  Eigen::VectorXd e = Eigen::VectorXd::Zero(3);
  for (int it = 0; it < 50; ++it) {
    const VecN th = VecN(target + e);
    e = -(Eigen::VectorXd(plant.gravityTorque(th)) - Eigen::VectorXd(model.gravityTorque(th))).cwiseQuotient(s.controller.kp);
  }
  Eigen::VectorXd last;
  setPoint(s, target, target, 5e-4, 4.0, [&](double, const Eigen::VectorXd& th, const Eigen::VectorXd&, double) { last = th; });
  MESSAGE("settled error ", (last - target).transpose(), ", closed form ", e.transpose());
  CHECK(e.cwiseAbs().maxCoeff() > 1e-4);  // the payload's weight is felt
  CHECK((last - target - e).cwiseAbs().maxCoeff() < 0.01 * e.cwiseAbs().maxCoeff());
}
