// The rolling kind (physics/constraints/rolling.h) through the generic mechanism, against the
// lecture's closed forms for the upright wheel (§3 "Unicycle"):
//  * from rest under constant torques: θ'' = τ_y/(I_a + m r²), φ'' = τ_z/I_z, x' = r cos φ θ', y' = r sin φ θ';
//  * with no torque it rolls a circle of radius r θ'/φ' at constant energy, pressed by f_normal = m g
//    and held on the circle by f_lat = m r θ' φ' (the centripetal force, not the rim's ω² r);
//  * the constraint force does no work: E(T) − E(0) = ∫ τ·θ' dt;
// and for a tilted disk (a rolling coin, where the contact point moves round the rim: the ḋ term)
// the velocity rows stay satisfied without any drift correction and energy is conserved.
#include <doctest/doctest.h>

#include <cmath>

#include "physics/constrained_mechanism.h"
#include "physics/constraints/rolling.h"

using namespace dyn;

namespace {

using Pos = Spatial::Pos;
constexpr double kR = 0.1, kM = 2.0, kG = 9.81;
constexpr double kIa = kM * kR * kR / 2, kId = kM * kR * kR / 4;

Spatial::Mat massless() { return Spatial::Mat::Zero(); }

// The wheel hung from the world by x, y, z, heading φ (about z), optionally a tilt β (about the
// heading), and spin θ (about the axle, y): q = (x, y, z, φ, [β,] θ).
MechanismModel<Spatial> wheel(bool tilt = false) {
  MechanismModel<Spatial> d;
  auto& t = d.tree;
  t.gravity << 0, 0, 0, 0, 0, -kG;
  int b = t.addBody(-1, JointType::Prismatic, Pos::UnitX(), Spatial::Transform(), massless());
  b = t.addBody(b, JointType::Prismatic, Pos::UnitY(), Spatial::Transform(), massless());
  b = t.addBody(b, JointType::Prismatic, Pos::UnitZ(), Spatial::Transform(), massless());
  b = t.addBody(b, JointType::Revolute, Pos::UnitZ(), Spatial::Transform(), massless());
  if (tilt) b = t.addBody(b, JointType::Revolute, Pos::UnitX(), Spatial::Transform(), massless());
  b = t.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::Transform(),
                Spatial::inertia(kM, Pos::Zero(), Eigen::Vector3d(kId, kIa, kId).asDiagonal()));
  d.constraints.push_back(std::make_shared<Rolling>(BodyRef::link(b), Pos::Zero(), Pos::UnitY(), kR, 0.0, 0.8));
  return d;
}

// An upright wheel's consistent state at (x, y, φ) rolling at θ', turning at φ'.
void upright(double phi, double theta_rate, double phi_rate, VecN& q, VecN& v) {
  q = VecN::Zero(5);
  v = VecN::Zero(5);
  q[2] = kR;
  q[3] = phi;
  v << kR * std::cos(phi) * theta_rate, kR * std::sin(phi) * theta_rate, 0, phi_rate, theta_rate;
}

}  // namespace

TEST_CASE("rolling: from rest under constant torques the wheel follows the closed form") {
  ConstrainedMechanism<Spatial> mech(wheel());
  VecN q, v;
  upright(0.3, 0, 0, q, v);
  const double tau_y = 0.05, tau_z = 0.002, T = 5.0, dt = 1e-3;
  VecN tau = VecN::Zero(5);
  tau[3] = tau_z;
  tau[4] = tau_y;
  StepOptions o;
  o.dt = dt;
  const long steps = std::lround(T / dt);
  for (long i = 0; i < steps; ++i) REQUIRE(step(mech, o, tau, q, v));
  const double th_dd = tau_y / (kIa + kM * kR * kR), ph_dd = tau_z / kId;
  CHECK(std::abs(v[4] - th_dd * T) < 1e-9);
  CHECK(std::abs(v[3] - ph_dd * T) < 1e-9);
  CHECK(std::abs(q[3] - (0.3 + 0.5 * ph_dd * T * T)) < 1e-9);
  CHECK(std::abs(q[4] - 0.5 * th_dd * T * T) < 1e-9);
  // x(T), y(T): ∫ r (cos φ, sin φ) θ' dt by Simpson's rule on 200 000 intervals (error ~1e-15).
  const int n = 200000;
  double x = 0, y = 0;
  for (int i = 0; i <= n; ++i) {
    const double t = T * i / n, w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
    const double phi = 0.3 + 0.5 * ph_dd * t * t, rate = kR * th_dd * t;
    x += w * rate * std::cos(phi);
    y += w * rate * std::sin(phi);
  }
  x *= T / n / 3;
  y *= T / n / 3;
  CHECK(std::abs(q[0] - x) < 1e-9);
  CHECK(std::abs(q[1] - y) < 1e-9);
  CHECK(std::abs(q[2] - kR) < 1e-12);
  CHECK(mech.residual(q, v) < 1e-12);
}

TEST_CASE("rolling: with no torque the wheel rolls a circle of radius r θ'/φ', held by m r θ' φ'") {
  ConstrainedMechanism<Spatial> mech(wheel());
  const double th = 20.0, ph = 1.5;  // rad/s: 2 m/s forward, a circle of radius 4/3 m
  VecN q, v;
  upright(0.0, th, ph, q, v);
  const VecN tau = VecN::Zero(5);
  const double E0 = mech.energy(q, v), radius = kR * th / ph;
  const Pos centre(0, radius, kR);  // turning left from the origin heading +x
  StepOptions o;
  o.dt = 1e-3;
  double worst_radius = 0, worst_energy = 0, worst_force = 0;
  double out[5];
  for (int i = 0; i < 4000; ++i) {
    const auto sol = mech.solve(q, v, tau);
    mech.constraintReport(0, sol, out);
    worst_force = std::max({worst_force, std::abs(out[1] - kM * kR * th * ph), std::abs(out[2] - kM * kG), std::abs(out[0])});
    CHECK(out[4] < 1e-12);  // the hand model does not slip
    REQUIRE(step(mech, o, tau, q, v));
    worst_radius = std::max(worst_radius, std::abs((Pos(q[0], q[1], q[2]) - centre).norm() - radius));
    worst_energy = std::max(worst_energy, std::abs(mech.energy(q, v) - E0) / E0);
  }
  CHECK(worst_radius < 1e-9);
  CHECK(worst_energy < 1e-12);
  CHECK(worst_force < 1e-9);
  // Rates kept to rounding over 4,000 steps (the stages work at the world origin, up to 2.7 m away:
  // a few ulp of r × f per step).
  CHECK(std::abs(v[4] - th) < 1e-11);
  CHECK(std::abs(v[3] - ph) < 1e-11);
}

TEST_CASE("rolling: the contact force does no work (energy change = work of the torques)") {
  ConstrainedMechanism<Spatial> mech(wheel());
  VecN q, v;
  upright(1.0, 5.0, -0.5, q, v);
  StepOptions o;
  o.dt = 5e-4;
  const double E0 = mech.energy(q, v);
  double work = 0;
  for (int i = 0; i < 6000; ++i) {
    const double t = i * o.dt;
    VecN tau = VecN::Zero(5);
    tau[3] = 0.01 * std::sin(3 * t);
    tau[4] = 0.05 * std::cos(2 * t);
    VecN q1 = q, v1 = v;
    REQUIRE(step(mech, o, tau, q1, v1));
    work += tau.dot(0.5 * (v + v1)) * o.dt;  // trapezoid: O(dt²) on the work, checked loosely below
    q = q1, v = v1;
  }
  const double dE = mech.energy(q, v) - E0;
  CHECK(std::abs(dE - work) < 1e-6 * std::max(1.0, std::abs(work)));
  CHECK(mech.residual(q, v) < 1e-12);
}

// A coin tilted by 0.3 rad, rolling and turning, q = (x, y, z, φ, β, θ), for 0.3 s without drift
// correction: the worst velocity-row residual and relative energy error.
std::pair<double, double> coinRun(double dt) {
  ConstrainedMechanism<Spatial> mech(wheel(true));
  VecN q = VecN::Zero(6), v = VecN::Zero(6);
  q[4] = 0.3;
  q[2] = kR * std::cos(0.3);
  v << 1.0, 0.0, 0.0, 4.0, 0.0, -12.0;
  projectVelocities(mech, q, v);
  REQUIRE(mech.residual(q, v) < 1e-12);
  StepOptions o;
  o.dt = dt;
  o.drift.kind = Drift::None;
  const double E0 = mech.energy(q, v);
  double worst_energy = 0, worst_residual = 0;
  for (long i = 0; i < std::lround(0.3 / dt); ++i) {
    REQUIRE(step(mech, o, VecN::Zero(6), q, v));
    worst_energy = std::max(worst_energy, std::abs(mech.energy(q, v) - E0) / E0);
    worst_residual = std::max(worst_residual, mech.residual(q, v));
  }
  CHECK(std::abs(q[4]) < 1.2);  // still on its rim
  return {worst_residual, worst_energy};
}

TEST_CASE("rolling: a tilted coin keeps its velocity rows without drift correction, at constant energy") {
  REQUIRE_FALSE(ConstrainedMechanism<Spatial>(wheel(true)).holonomic());
  // What is left is RK4's own error: fourth order (a wrong J'θ' — e.g. the rim's centripetal term kept,
  // or ḋ dropped — would drift at any dt, ratio ~1).
  const auto [r1, e1] = coinRun(1e-4);
  const auto [r2, e2] = coinRun(5e-5);
  MESSAGE("coin, dt 1e-4 → 5e-5: residual " << r1 << " → " << r2 << ", energy " << e1 << " → " << e2);
  CHECK(r2 < 2e-8);
  CHECK(e2 < 1e-7);
  CHECK(r1 / r2 > 12);
  CHECK(e1 / e2 > 12);
}

TEST_CASE("rolling: the x, y rows have no position form; bad parameters are refused") {
  ConstrainedMechanism<Spatial> mech(wheel());
  VecN q, v;
  upright(0.0, 10.0, 0.0, q, v);
  q[0] = 5.0;  // anywhere on the ground is consistent
  q[3] = 2.0;
  CHECK(mech.residual(q) < 1e-15);
  q[2] = kR + 0.01;  // lifted: the z row's φ sees it
  CHECK(std::abs(mech.residual(q) - 0.01) < 1e-15);
  CHECK_THROWS(Rolling(BodyRef::link(4), Pos::Zero(), Pos::UnitY(), 0.0, 0.0, 0.8));
  CHECK_THROWS(Rolling(BodyRef::link(4), Pos::Zero(), Pos::UnitY(), 0.1, 0.0, -1.0));
  CHECK_THROWS(Rolling(BodyRef::world(), Pos::Zero(), Pos::UnitY(), 0.1, 0.0, 0.8));
}

TEST_CASE("rolling: its rows, read in place, are the point Jacobian's translation rows at the contact, bit for bit") {
  // Rolling reads the wheel's X_world and S_w itself: J must be k.addPointJacobian(wheel, P, x y z, −1)
  // exactly, at a tilted, turned wheel (every column counts).
  MechanismModel<Spatial> d;
  d.tree.gravity << 0, 0, 0, 0, 0, -9.81;
  const Spatial::Mat none = Spatial::Mat::Zero();
  int b = d.tree.addBody(-1, JointType::Prismatic, Spatial::Pos::UnitX(), Spatial::Transform(), none);
  b = d.tree.addBody(b, JointType::Prismatic, Spatial::Pos::UnitY(), Spatial::Transform(), none);
  b = d.tree.addBody(b, JointType::Prismatic, Spatial::Pos::UnitZ(), Spatial::Transform(), none);
  b = d.tree.addBody(b, JointType::Revolute, Spatial::Pos::UnitZ(), Spatial::Transform(), none);
  b = d.tree.addBody(b, JointType::Revolute, Spatial::Pos::UnitX(), Spatial::Transform(), none);  // tilt
  const Eigen::Vector3d I(0.005, 0.01, 0.005);
  b = d.tree.addBody(b, JointType::Revolute, Spatial::Pos::UnitY(), Spatial::Transform(), Spatial::inertia(2.0, Spatial::Pos::Zero(), I.asDiagonal()));
  const auto rolling = std::make_shared<Rolling>(BodyRef::link(b), Spatial::Pos::Zero(), Spatial::Pos::UnitY(), 0.1, 0.0, 0.8);
  d.constraints.push_back(rolling);
  ConstrainedMechanism<Spatial> mech(d);
  VecN q(6);
  q << 0.2, -0.3, 0.09, 0.7, 0.3, 1.9;
  mech.stage(q);
  const auto& k = mech.kinematics();
  VecN phi = VecN::Zero(3);
  MatN J = MatN::Zero(3, 6), A = MatN::Zero(3, 0), J_ref = MatN::Zero(3, 6), A_ref = MatN::Zero(3, 0);
  rolling->position(k, 0, phi, J, A);
  k.addPointJacobian(BodyRef::link(b), rolling->point(k), {false, false, false, true, true, true}, -1.0, 0, J_ref, A_ref);
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 6; ++j) CHECK(J(r, j) == J_ref(r, j));
  CHECK(phi[2] == -rolling->point(k).z());
  CHECK(J.norm() > 0.1);
}
