// External forces (physics/mechanism.h ExternalForce, physics/forces.h) and the books (integrate.h):
//  * a passive planar arm under a constant tip push equals a reference integration of
//    M q'' + h = J(q)ᵀF (the force through the controller's own point Jacobian, at every stage of a
//    test-local RK4 at dt/8) to 1e-8 rad at dt 1 ms over 1 s, and the error falls at fourth order;
//  * the books: W of a constant push is F·(p(t) − p(0)) exactly, and E − E0 − W is at RK4's error,
//    falling at fourth order; with tanh friction E − E0 = W + D likewise;
//  * a push that switches on at a step boundary acts from that step on (no stage of the step before);
//  * a spring to the world displaced by Δ pulls with k Δ: M q'' = J_Pᵀ k Δ − G at rest.
#include <doctest/doctest.h>

#include <Eigen/Cholesky>
#include <cmath>

#include "tests/physics/reference_rk4.h"
#include "physics/constrained_mechanism_impl.h"
#include "physics/forces.h"
#include "tests/physics/arms.h"

using namespace dyn;

namespace {

using Pos = Planar::Pos;
const Pos kTip(0.2, 0.0);            // the arm's last link is 0.2 m long
const Eigen::Vector2d kPush(2.0, -1.0);  // N, world axes

// The test arm without gravity: the push alone moves it (under gravity this light arm whips through
// chaotic swings, where any error grows by e^{λt}).
TreeModel<Planar> arm() {
  TreeModel<Planar> t = test::planarArm();
  t.gravity.setZero();
  return t;
}

MechanismModel<Planar> pushedArm(const ForceProfile& profile = {}) {
  MechanismModel<Planar> d;
  d.tree = arm();
  d.forces.push_back(std::make_shared<PushForce<Planar>>(BodyRef::link(2), kTip, Planar::Vec(0.0, kPush.x(), kPush.y()), profile));
  return d;
}

VecN startAngles() { return (VecN(3) << 0.3, -0.8, 0.5).finished(); }

// The engine's run: (q, v) at T, and the books.
struct Run {
  VecN q, v;
  Books books;
  double energy_error = 0;  // max |E − E0 − W − D| over the run
};
Run engineRun(MechanismModel<Planar> d, double dt, double T, double t0 = 0.0) {
  ConstrainedMechanism<Planar> mech(std::move(d));
  StepOptions o;
  o.dt = dt;
  o.drift.kind = Drift::None;
  Run r{startAngles(), VecN::Zero(3), {}, 0.0};
  const VecN tau = VecN::Zero(3);
  mech.setTime(t0);
  const double e0 = mech.energy(r.q, r.v);
  for (long k = 0; k < std::lround(T / dt); ++k) {
    REQUIRE(step(mech, o, tau, r.q, r.v));
    const Books& b = mech.books();
    r.energy_error = std::max(r.energy_error, std::abs(mech.energy(r.q, r.v) - e0 - b.work - b.friction));
  }
  r.books = mech.books();
  return r;
}

// The reference: its own RK4 on M(q) q'' = J(q)ᵀF − h(q, q') with M, h and J from a mechanism with no
// forces (the tree algorithms and the controller's point Jacobian), F applied at every stage.
VecN referenceRun(double dt, double T) {
  MechanismModel<Planar> d;
  d.tree = arm();
  ConstrainedMechanism<Planar> arm(d);
  const Planar::Vec F(0.0, kPush.x(), kPush.y());
  auto accel = [&](const VecN& q, const VecN& v) {
    MatN J;
    VecN jd;
    arm.pointJacobian(2, kTip, q, v, J, jd);
    const VecN h = arm.inverseDynamics(q, v, VecN::Zero(3));
    const Eigen::MatrixXd M = arm.massMatrix(q);
    return VecN(M.ldlt().solve(Eigen::VectorXd(J.transpose() * F - h)));
  };
  return dyn::test::referenceRk4(accel, startAngles(), VecN::Zero(3), dt, std::lround(T / dt));
}

Pos tipPosition(const VecN& q) {
  MechanismModel<Planar> d;
  d.tree = test::planarArm();
  ConstrainedMechanism<Planar> arm(d);
  return arm.pointPosition(2, kTip, q);
}

}  // namespace

TEST_CASE("a passive arm under a constant tip push is M q'' + h = J(q)ᵀF, at fourth order") {
  const double T = 1.0;
  const VecN ref = referenceRun(1.25e-4, T);
  double err[3];
  const double dts[3] = {4e-3, 2e-3, 1e-3};
  for (int i = 0; i < 3; ++i) err[i] = (engineRun(pushedArm(), dts[i], T).q - ref).lpNorm<Eigen::Infinity>();
  MESSAGE("|q − q_ref| at dt 4, 2, 1 ms: " << err[0] << ", " << err[1] << ", " << err[2]);
  CHECK(err[2] < 1e-8);
  CHECK(err[0] / err[1] > 12.0);  // fourth order: 16
  CHECK(err[1] / err[2] > 12.0);
}

TEST_CASE("the books: a constant push's work is F·Δp, and E − E0 − W falls at fourth order") {
  const double T = 1.0;
  const Run fine = engineRun(pushedArm(), 1e-3, T), coarse = engineRun(pushedArm(), 2e-3, T);
  const double exact = kPush.dot(tipPosition(fine.q) - tipPosition(startAngles()));
  MESSAGE("W = " << fine.books.work << " J, F·Δp = " << exact << " J; |E − E0 − W| at 2, 1 ms: " << coarse.energy_error << ", "
                 << fine.energy_error);
  CHECK(std::abs(fine.books.work - exact) < 1e-9 * std::abs(exact) + 1e-12);
  CHECK(fine.books.friction == 0.0);
  CHECK(fine.energy_error < 1e-8);
  CHECK(coarse.energy_error / fine.energy_error > 12.0);
}

TEST_CASE("the books with tanh friction: E − E0 = W + D at fourth order, D ≤ 0") {
  auto withFriction = [] {
    MechanismModel<Planar> d = pushedArm();
    JointProperties j;
    j.viscous = 0.01, j.coulomb = 0.05, j.coulomb_width = 0.2;
    d.joints.assign(3, j);
    return d;
  };
  const Run fine = engineRun(withFriction(), 1e-3, 1.0), coarse = engineRun(withFriction(), 2e-3, 1.0);
  MESSAGE("D = " << fine.books.friction << " J; |E − E0 − W − D| at 2, 1 ms: " << coarse.energy_error << ", " << fine.energy_error);
  CHECK(fine.books.friction < 0.0);
  CHECK(fine.energy_error < 1e-8);
  CHECK(coarse.energy_error / fine.energy_error > 12.0);
  // The law itself: F_c tanh(θ'/w) + b θ', smooth and odd.
  JointProperties j;
  j.viscous = 0.5, j.coulomb = 2.0, j.coulomb_width = 0.1;
  CHECK(j.friction(0.1) == doctest::Approx(0.05 + 2.0 * std::tanh(1.0)));
  CHECK(j.friction(-0.3) == doctest::Approx(-j.friction(0.3)));
}

TEST_CASE("a push switched on at a step boundary acts from that step on, none of it on the step before") {
  // Started at t = 0.1 s = 100 steps: the run from 0 equals a run that starts at 0.1 s with the push on.
  const double dt = 1e-3;
  MechanismModel<Planar> d = pushedArm({0.1, 0.0, 0.0});
  ConstrainedMechanism<Planar> mech(d);
  StepOptions o;
  o.dt = dt;
  o.drift.kind = Drift::None;
  VecN q = startAngles(), v = VecN::Zero(3);
  const VecN tau = VecN::Zero(3);
  for (int k = 0; k < 100; ++k) {
    mech.setTime(k * dt);
    REQUIRE(step(mech, o, tau, q, v));
  }
  // The first 100 steps: the free motion (W = 0 to rounding), no push leaked into the last one.
  CHECK(std::abs(mech.books().work) < 1e-15);
  MechanismModel<Planar> free;
  free.tree = arm();
  ConstrainedMechanism<Planar> fall(free);
  VecN qf = startAngles(), vf = VecN::Zero(3);
  for (int k = 0; k < 100; ++k) REQUIRE(step(fall, o, tau, qf, vf));
  CHECK((q - qf).lpNorm<Eigen::Infinity>() == 0.0);
  // The next step feels the push.
  mech.setTime(100 * dt);
  REQUIRE(step(mech, o, tau, q, v));
  REQUIRE(step(fall, o, tau, qf, vf));
  CHECK((q - qf).lpNorm<Eigen::Infinity>() > 1e-7);
}

TEST_CASE("a spring to the world pulls with k Δ through J_Pᵀ; a force on the world is refused") {
  MechanismModel<Planar> d;
  d.tree = test::planarArm();
  const VecN q0 = startAngles();
  ConstrainedMechanism<Planar> plain(d);
  // The anchor Δ away from the tip at rest: the spring pulls with k Δ, so M q'' = J_Pᵀ k Δ − G at q0.
  const Pos tip = plain.pointPosition(2, kTip, q0), delta(0.01, -0.02);
  d.forces.push_back(std::make_shared<WorldSpring<Planar>>(BodyRef::link(2), kTip, Pos(tip + delta), 500.0, 3.0));
  ConstrainedMechanism<Planar> sprung(d);
  MatN J;
  VecN jd;
  plain.pointJacobian(2, kTip, q0, VecN::Zero(3), J, jd);
  const VecN expected = plain.massMatrix(q0).ldlt().solve(Eigen::VectorXd(J.bottomRows(2).transpose() * (500.0 * delta) -
                                                                             plain.gravityTorque(q0)));
  VecN a;
  sprung.accelerations(q0, VecN::Zero(3), VecN::Zero(3), nullptr, a);
  CHECK((a - expected).lpNorm<Eigen::Infinity>() < 1e-10 * expected.lpNorm<Eigen::Infinity>());
  // A force on the world is refused.
  MechanismModel<Planar> bad;
  bad.tree = test::planarArm();
  bad.forces.push_back(std::make_shared<PushForce<Planar>>(BodyRef::world(), Pos::Zero(), Planar::Vec::Zero(), ForceProfile{}));
  CHECK(bad.validate().find("external force 0") == 0);
}
