// BulletChain (physics/bullet/bullet_chain.h): Bullet's btMultiBody of a planar chain of any size.
//  * Bullet's step is semi-implicit Euler on its own articulated-body dynamics: θ'₁ = θ'₀ + dt θ''(θ₀, θ'₀),
//    then θ₁ = θ₀ + dt θ'₁. The hand engine stepped the same way (ABA) from the same state must give
//    the same states to rounding, whatever dt: a check of the chain's masses, inertias, centres of
//    mass, joint placements and signs all at once. Measured: 3e-16 rad over 0.3 s at dt = 1 ms; the
//    bound, 1e-11, leaves room for another compiler's rounding and is 1e8× below the scheme's own
//    first-order error (1.5e-3 rad against RK4), which is the size a modelling slip would show.
//  * chains longer than kMaxDof build and step (100 links), agreeing with the hand engine.
#include <doctest/doctest.h>

#include <cmath>
#include <stdexcept>

#include "physics/bullet/bullet_chain.h"

using namespace dyn;
using dyn::bullet::BulletChain;

namespace {

struct HandChain {
  TreeModel<Planar> model;
  TreeData<Planar> data;
  Eigen::VectorXd q, qd, tau, qdd;
  HandChain(const TreeModel<Planar>& m, const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0)
      : model(m), data(model), q(q0), qd(qd0), tau(Eigen::VectorXd::Zero(m.dof())), qdd(m.dof()) {}
  Eigen::VectorXd accel(const Eigen::VectorXd& qq, const Eigen::VectorXd& vv) {
    forwardKinematics(model, qq, vv, data);
    aba(model, data, vv, tau, qdd);
    return qdd;
  }
  void eulerStep(double dt) {  // Bullet's order: velocities first, then positions with the new ones
    qd += dt * accel(q, qd);
    q += dt * qd;
  }
  void rk4Step(double dt) {
    const Eigen::VectorXd v1 = qd, a1 = accel(q, qd);
    const Eigen::VectorXd v2 = qd + 0.5 * dt * a1, a2 = accel(q + 0.5 * dt * v1, v2);
    const Eigen::VectorXd v3 = qd + 0.5 * dt * a2, a3 = accel(q + 0.5 * dt * v2, v3);
    const Eigen::VectorXd v4 = qd + dt * a3, a4 = accel(q + dt * v3, v4);
    q += dt / 6 * (v1 + 2 * v2 + 2 * v3 + v4);
    qd += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  }
};

// A bent, moving start (not the symmetric outstretched one, so every term of the dynamics acts).
void startState(int n, Eigen::VectorXd& q, Eigen::VectorXd& qd) {
  q.resize(n), qd.resize(n);
  for (int i = 0; i < n; ++i) q[i] = (i == 0 ? -0.6 : 0.3) + 0.2 * std::sin(1.7 * i), qd[i] = 0.5 * std::cos(0.9 * i);
}

}  // namespace

TEST_CASE("a 5-link chain: Bullet's btMultiBody and the hand ABA take the same semi-implicit Euler steps") {
  const TreeModel<Planar> model = uniformPlanarChain(5, 0.3, 1.0);
  Eigen::VectorXd q0, qd0;
  startState(5, q0, qd0);
  const double dt = 1e-3, duration = 0.3;
  BulletChain bullet(model, dt, q0, qd0);
  HandChain hand(model, q0, qd0), exact(model, q0, qd0);
  double gap = 0, first_order = 0, first_step = 0;
  Eigen::VectorXd qb, vb;
  for (int k = 0; k < int(std::lround(duration / dt)); ++k) {
    bullet.step(hand.tau);
    hand.eulerStep(dt);
    for (int s = 0; s < 10; ++s) exact.rk4Step(dt / 10);  // the reference: RK4 at dt/10, error ~1e-14
    bullet.state(qb, vb);
    gap = std::max(gap, (qb - hand.q).cwiseAbs().maxCoeff());
    if (k == 0) first_step = (vb - hand.qd).cwiseAbs().maxCoeff();
    first_order = std::max(first_order, (hand.q - exact.q).cwiseAbs().maxCoeff());
  }
  const Eigen::Vector2d tip_hand = [&] {
    positionKinematics(hand.model, hand.q, hand.data);
    return pointPosition(hand.data, 4, Planar::Pos(0.3, 0.0));
  }();
  const double tip_gap = (bullet.pointPosition(4, {0.3, 0.0}) - tip_hand).norm();
  INFO("first step |Δθ'| " << first_step << " rad/s; max |Δθ| over 0.3 s " << gap << " rad; tip gap " << tip_gap
                           << " m; first-order error of the scheme " << first_order << " rad");
  // One step: the same θ'' to rounding. The run: rounding only, far below the first-order error.
  CHECK(first_step < 1e-12);
  CHECK(gap < 1e-11);
  CHECK(tip_gap < 1e-11);
  CHECK(first_order > 1e-4);
}

TEST_CASE("a 100-link chain (beyond kMaxDof) builds, steps and agrees with the hand ABA") {
  const int n = 100;
  const TreeModel<Planar> model = uniformPlanarChain(n, 0.05, 0.1);
  Eigen::VectorXd q0, qd0;
  startState(n, q0, qd0);
  const double dt = 1e-3;
  BulletChain bullet(model, dt, q0, qd0);
  HandChain hand(model, q0, qd0);
  for (int k = 0; k < 50; ++k) {
    bullet.step(hand.tau);
    hand.eulerStep(dt);
  }
  Eigen::VectorXd qb, vb;
  bullet.state(qb, vb);
  INFO("max |Δθ| after 50 steps " << (qb - hand.q).cwiseAbs().maxCoeff() << " rad");
  CHECK((qb - hand.q).cwiseAbs().maxCoeff() < 1e-11);
  CHECK_THROWS_AS(bullet.step(Eigen::VectorXd::Zero(3)), std::invalid_argument);
  CHECK_THROWS_AS(BulletChain(model, 0.0, q0, qd0), std::invalid_argument);
}
