// The motion-control lab (labs/motion_control) against the lecture's §4 claims, cheap runs only:
//  * τ = 0 without friction conserves energy to 1e-6 J in 1 s (RK4), rigid and flexible (springs included);
//  * with friction and a controller, E − E0 equals the work of τ plus the friction's (trapezoid);
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
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <string>

#include "labs/motion_control/lab.h"
#include "labs/run.h"

using namespace dyn;
using namespace dyn::motion_control;

namespace {

const std::string kFile = "motion_control.json (test)";

json config(const json& patch) { return mergePatch(loadJsonFile(defaultConfigPath("motion_control")), patch); }

std::unique_ptr<Lab> makeLab(const json& patch) {
  const LabEntry* entry = findLab("motion_control");
  REQUIRE(entry != nullptr);
  return buildLab(*entry, config(patch), kFile);
}

Settings settings(const json& patch) {
  const json c = config(patch);
  return parseSettings(JsonView(c, kFile));
}

std::string inputError(const json& patch) {
  try {
    makeLab(patch);
  } catch (const InputError& e) {
    return e.path() + ": " + e.expected();
  }
  return "accepted";
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

}  // namespace

TEST_CASE("motion_control: tau = 0 without friction conserves energy, rigid and flexible") {
  for (bool flexible : {false, true}) {
    CAPTURE(flexible);
    const auto lab = makeLab({{"controller", {{"kind", "none"}}},
                              {"mechanism", {{"friction", noFriction()}, {"flexible", {{"enabled", flexible}}}}},
                              {"simulation", {{"duration", 1.0}, {"dt", flexible ? 2.5e-4 : 1e-3}}}});
    const RunResult r = runEngine(*lab, Engine::Hand);
    REQUIRE(r.failure.empty());
    double worst = 0;
    for (double e : r.trace.series("energy")) worst = std::max(worst, std::abs(e - r.trace.at(0, "energy")));
    // The falling arm converts ~20 J: 1e-6 J is RK4's error at dt = 1 ms (flexible: the rotor–spring
    // modes near 200 rad/s need dt = 0.25 ms for the same; at 1 ms RK4 loses 7e-4 J in 1 s).
    CHECK(worst < 1e-6);
    CHECK(lab->metrics(r.trace)["energy_initial"].get<double>() == doctest::Approx(r.trace.at(0, "energy")));
  }
}

TEST_CASE("motion_control: with friction, E − E0 = work of τ and of friction") {
  const auto lab = makeLab({{"simulation", {{"duration", 1.5}}}});
  const RunResult r = runEngine(*lab, Engine::Hand);
  REQUIRE(r.failure.empty());
  const json m = lab->metrics(r.trace);
  double moved = 0;  // |W| at its largest: the scale of the balance
  for (double w : r.trace.series("work")) moved = std::max(moved, std::abs(w));
  CHECK(moved > 1.0);
  // The trapezoid rule over 1 ms steps against RK4: 1e-3 of the work done.
  CHECK(m["energy_drift"].get<double>() < 1e-3 * moved);
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
  const auto lab = makeLab({{"simulation", {{"duration", 1.0}}}});
  const RunResult h = runEngine(*lab, Engine::Hand), b = runEngine(*lab, Engine::Bullet);
  REQUIRE(h.failure.empty());
  REQUIRE(b.failure.empty());
  const json a = lab->agreement(h.trace, b.trace);
  MESSAGE("hand vs Bullet: max |Δθ| = ", a["max_dq"].get<double>(), " rad");
  CHECK(a["max_dq"].get<double>() < 5e-3);
}

TEST_CASE("motion_control: bad inputs get one line naming the path") {
  CHECK(inputError({{"controller", {{"control_period", 0.0015}}}}) ==
        "/controller/control_period: expected a whole multiple of the simulation step /simulation/dt");
  CHECK(inputError({{"mechanism", {{"torque_limit", {1.0, 2.0}}}}}).rfind("/mechanism/torque_limit", 0) == 0);
  CHECK(inputError({{"controller", {{"kind", "lqr"}}}}).rfind("/controller/kind", 0) == 0);
  CHECK(inputError({{"trajectory", {{"move_time", 0.0}}}}).rfind("/trajectory/move_time", 0) == 0);
  CHECK(inputError(json::object()) == "accepted");
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
