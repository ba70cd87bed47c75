// External forces in Bullet's spatial builder (physics/bullet/spatial_mechanism.cpp): the description's
// push (a force and a torque at a link point off its centre of mass, on a link whose inertia has
// products, so Bullet's link frame is turned onto principal axes) applied by Bullet at each step from
// the state at the step's start:
//  * Bullet's first step is v₁ = v₀ + dt a(q₀, v₀): (v₁ − v₀)/dt must be the hand engine's forward
//    dynamics with the push (J_Pᵀ F at every stage) to rounding, whatever dt;
//  * a held arm: τ = G − J_Pᵀ F with J_P from finite differences of the point's position (independent of
//    the engines' Jacobians) keeps the pushed arm at rest in both engines; τ = G alone does not;
//  * over 0.5 s with the push switched on at 0.1 s (the step's time is read), Bullet follows the hand
//    engine's RK4 at dt/8 to first order in dt; its books hold the push's work.
#include <doctest/doctest.h>

#include <cmath>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/forces.h"
#include "tests/physics/arms.h"

using namespace dyn;
using dyn::bullet::BulletMechanism;
using Pos = Spatial::Pos;

namespace {

const Pos kPoint(0.35, 0.04, -0.03);  // on link 2, 0.2 m beyond its centre of mass
const Pos kForce(4.0, -3.0, 6.0);     // N, world axes
const Pos kTorque(0.2, 0.5, -0.3);    // N·m

MechanismModel<Spatial> pushedArm(const ForceProfile& profile, bool with_torque = true) {
  MechanismModel<Spatial> d;
  d.tree = test::spatialArm();
  Spatial::Vec F;
  F << (with_torque ? kTorque : Pos::Zero()), kForce;
  d.forces.push_back(std::make_shared<PushForce<Spatial>>(BodyRef::link(2), kPoint, F, profile));
  return d;
}

VecN startAngles() { return (VecN(3) << 0.4, -0.6, 1.1).finished(); }
VecN startRates() { return (VecN(3) << 0.7, -0.4, 1.2).finished(); }

}  // namespace

TEST_CASE("spatial push: Bullet's first step is the hand engine's forward dynamics with the push, to rounding") {
  const MechanismModel<Spatial> d = pushedArm(ForceProfile{});
  const VecN q = startAngles(), v = startRates(), tau = (VecN(3) << 0.3, -1.0, 0.4).finished();
  ConstrainedMechanism<Spatial> hand(d);
  const VecN a = hand.solve(q, v, tau).qdd;
  MechanismModel<Spatial> unpushed = d;
  unpushed.forces.clear();
  ConstrainedMechanism<Spatial> free(unpushed);
  const VecN a_free = free.solve(q, v, tau).qdd;
  for (double dt : {1e-3, 1e-4}) {
    BulletMechanism<Spatial> b(d, dt, q, v);
    b.step(tau, 0.0);
    VecN q1, v1;
    b.state(q1, v1);
    const VecN a_bullet = (v1 - v) / dt;
    MESSAGE("dt " << dt << ": hand θ'' " << a.transpose() << ", Bullet " << a_bullet.transpose() << ", without the push "
                  << a_free.transpose());
    CHECK((a_bullet - a).cwiseAbs().maxCoeff() < 1e-9 * a.cwiseAbs().maxCoeff());
  }
  // The push changes θ'' by far more than that tolerance: the check sees a missing or misplaced push.
  CHECK((a - a_free).cwiseAbs().maxCoeff() > 1e5 * 1e-9 * a.cwiseAbs().maxCoeff());
}

TEST_CASE("spatial push: a held arm's torque change is J_Pᵀ F (finite differences), in both engines") {
  const MechanismModel<Spatial> d = pushedArm(ForceProfile{}, false);
  const VecN q = startAngles();
  ConstrainedMechanism<Spatial> hand(d);
  // J_P by central differences of the point's position: independent of either engine's Jacobian.
  Eigen::Matrix<double, 3, 3> Jp;
  const double h = 1e-6;
  for (int j = 0; j < 3; ++j) {
    VecN qp = q, qm = q;
    qp[j] += h, qm[j] -= h;
    Jp.col(j) = (hand.pointPosition(2, kPoint, qp) - hand.pointPosition(2, kPoint, qm)) / (2 * h);
  }
  const VecN G = hand.gravityTorque(q);
  const VecN held = G - Jp.transpose() * kForce;
  const double dt = 1e-3;
  StepOptions o;
  o.dt = dt;
  o.drift.kind = Drift::None;
  auto drift = [&](const VecN& tau) {
    BulletMechanism<Spatial> b(d, dt, q, VecN::Zero(3));
    VecN qh = q, vh = VecN::Zero(3), qb, vb;
    for (int k = 0; k < 300; ++k) {
      REQUIRE(step(hand, o, tau, qh, vh));
      b.step(tau, double(k) * dt);
    }
    b.state(qb, vb);
    return std::pair((qh - q).cwiseAbs().maxCoeff(), (qb - q).cwiseAbs().maxCoeff());
  };
  const auto [hand_held, bullet_held] = drift(held);
  const auto [hand_g, bullet_g] = drift(G);
  MESSAGE("after 0.3 s, τ = G − J_PᵀF: hand |Δq| " << hand_held << ", Bullet " << bullet_held << "; τ = G: " << hand_g << ", " << bullet_g);
  // Finite differences leave ~1e-10 of J_P: the arm creeps by ~1e-9 rad; unheld it falls away by 0.1 rad.
  CHECK(hand_held < 1e-7);
  CHECK(bullet_held < 1e-7);
  CHECK(hand_g > 1e-2);
  CHECK(bullet_g > 1e-2);
}

TEST_CASE("spatial push: Bullet follows the hand engine to first order in dt, and books the push's work") {
  const ForceProfile later{0.1, 0.05, 0.0};  // on at 0.1 s, ramped over 50 ms: Bullet must read the step's time
  const MechanismModel<Spatial> d = pushedArm(later);
  const double T = 0.5;
  const VecN tau = VecN::Zero(3);
  auto hand = [&](double dt) {
    ConstrainedMechanism<Spatial> m(d);
    StepOptions o;
    o.dt = dt;
    o.drift.kind = Drift::None;
    VecN q = startAngles(), v = startRates();
    for (long k = 0; k < std::lround(T / dt); ++k) REQUIRE(step(m, o, tau, q, v));
    return q;
  };
  auto bullet = [&](const MechanismModel<Spatial>& model, double dt, Books* books) {
    BulletMechanism<Spatial> b(model, dt, startAngles(), startRates());
    for (long k = 0; k < std::lround(T / dt); ++k) b.step(tau, double(k) * dt);
    VecN q, v;
    b.state(q, v);
    if (books) {
      *books = b.books();
      // E1 − E0 = W for a conservative arm: kinetic + potential from the hand engine's energy at both ends.
      ConstrainedMechanism<Spatial> m(model);
      const double E0 = m.energy(startAngles(), startRates()), E1 = m.energy(q, v);
      MESSAGE("Bullet at dt " << dt << ": E1 − E0 = " << E1 - E0 << " J, books W = " << books->work << " J");
      CHECK(std::abs((E1 - E0) - books->work) < 0.1 * std::abs(books->work) + 0.05);
    }
    return q;
  };
  const VecN ref = hand(1.25e-4);
  Books books;
  const double coarse = (bullet(d, 1e-3, &books) - ref).cwiseAbs().maxCoeff();
  const double fine = (bullet(d, 5e-4, nullptr) - ref).cwiseAbs().maxCoeff();
  MechanismModel<Spatial> unpushed = d;
  unpushed.forces.clear();
  const double apart = (bullet(unpushed, 1e-3, nullptr) - ref).cwiseAbs().maxCoeff();
  MESSAGE("Bullet |q − q_hand| after 0.5 s: dt 1 ms " << coarse << " rad, 0.5 ms " << fine << " rad; unpushed " << apart << " rad");
  // Semi-implicit Euler's global error is O(dt): a few mrad at 1 ms over 0.5 s of a swing with
  // θ'' ~ 10–50 rad/s², halving with dt. The push moves the arm 20× farther than that.
  CHECK(coarse < 1e-2);
  CHECK(coarse / fine == doctest::Approx(2.0).epsilon(0.25));
  CHECK(apart > 20 * coarse);
  CHECK(std::abs(books.work) > 0.1);  // the push does work on the swinging arm (and gravity is potential)
}
