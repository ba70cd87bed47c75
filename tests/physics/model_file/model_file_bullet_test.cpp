// Loaded model files run in Bullet too (physics/bullet's spatial builder with loop closures): the
// four-bar's connect as a btMultiBodyPoint2Point, the slider crank's weld as a btMultiBodyFixedConstraint,
// against the hand engine from the same file (Bullet is first order, semi-implicit Euler at dt: the
// tolerances are its error over the run, measured at two steps), and the closure force against the
// hand engine's η over the first step (rows and signs of Bullet's constraints).
#include <doctest/doctest.h>

#include <cmath>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"

using namespace dyn;

namespace {

std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

struct Agreement {
  double dq = 0;        // max |q_bullet − q_hand|∞ over the run
  double residual = 0;  // max |φ(q_bullet)|∞ (the hand description's closure, at Bullet's state)
  double force = 0;     // |f_bullet − f_hand| of the first closure after the first step, relative
};

Agreement compare(const char* name, double T, double dt, int iterations = 30) {
  model_file::LoadedModel file = model_file::load(model(name));
  file.mechanism.bullet.solver_iterations = iterations;
  ConstrainedMechanism<Spatial> hand(file.mechanism);
  const int n = hand.n();
  VecN q = file.q0, v = VecN::Zero(n);
  bullet::BulletMechanism<Spatial> bt(file.mechanism, dt, q, v);
  StepOptions o;
  o.dt = dt;
  const VecN tau = VecN::Zero(n);
  const Spatial::Vec f0 = hand.constraintForce(0, hand.solve(q, v, tau));
  Agreement a;
  for (int k = 0; k < int(std::lround(T / dt)); ++k) {
    REQUIRE(step(hand, o, tau, q, v));
    bt.step(tau);
    VecN qb, vb;
    bt.state(qb, vb);
    if (k == 0) a.force = (bt.constraintForce(0) - f0).norm() / std::max(1.0, f0.norm());
    a.dq = std::max(a.dq, (qb - q).lpNorm<Eigen::Infinity>());
    a.residual = std::max(a.residual, hand.residual(qb));
  }
  MESSAGE(name << " dt " << dt << ": |q_bullet - q_hand| " << a.dq << ", |phi(q_bullet)| " << a.residual
               << ", first-step force " << a.force << " (" << bt.describe() << ")");
  return a;
}

}  // namespace

TEST_CASE("four-bar, five-bar and slider crank from files in Bullet agree with the hand engine") {
  for (const char* name : {"fourbar.xml", "slider_crank.xml", "fivebar.xml"}) {
    CAPTURE(std::string(name));
    // Trajectories at Bullet's defaults (PGS 30): its error is first order in dt, so it shrinks with dt.
    const Agreement coarse = compare(name, 1.0, 2e-3), fine = compare(name, 1.0, 1e-3);
    CHECK(fine.dq < 0.1);
    CHECK(fine.dq < 0.75 * coarse.dq);
    CHECK(fine.residual < 1e-3);
    CHECK(fine.residual < 0.75 * coarse.residual);
    // The closure's force over the first step from rest is the hand engine's η, once PGS has converged
    // (at 30 iterations the slider crank's weld force is still 1.4 % short).
    CHECK(compare(name, 1e-3, 1e-3, 300).force < 1e-9);
  }
}

TEST_CASE("armature in Bullet: rotor links geared to the joints follow the hand engine's M_ii += a") {
  // geared_arm.xml passive from rest, 1 s: Bullet (rotors geared 1000:1, first order) against the hand
  // engine (RK4) with armature, and against the hand engine without: the rotors must bring Bullet to
  // the armature's motion, its error shrinking with dt.
  model_file::LoadedModel file = model_file::load(model("geared_arm.xml"));
  MechanismModel<Spatial> bare = file.mechanism;
  for (JointProperties& j : bare.joints) j.armature = 0;
  auto run = [&](double dt, double& to_bare, double& drift) {
    ConstrainedMechanism<Spatial> hand(file.mechanism), none(bare);
    const int n = hand.n();
    VecN q = file.q0, v = VecN::Zero(n), qn = q, vn = v;
    bullet::BulletMechanism<Spatial> bt(file.mechanism, dt, q, v);
    StepOptions o;
    o.dt = dt;
    const VecN tau = VecN::Zero(n);
    const double e0 = hand.energy(q, v);
    double dq = 0;
    to_bare = drift = 0;
    for (int k = 0; k < int(std::lround(1.0 / dt)); ++k) {
      REQUIRE(step(hand, o, tau, q, v));
      REQUIRE(step(none, o, tau, qn, vn));
      bt.step(tau);
      VecN qb, vb;
      bt.state(qb, vb);
      dq = std::max(dq, (qb - q).lpNorm<Eigen::Infinity>());
      to_bare = std::max(to_bare, (qn - q).lpNorm<Eigen::Infinity>());
      drift = std::max(drift, std::abs(hand.energy(qb, vb) - e0));  // Bullet's state in the description's energy
    }
    MESSAGE("geared arm dt " << dt << ": |q_bullet - q_hand| " << dq << ", |q_hand(no armature) - q_hand| " << to_bare
                             << ", Bullet's |E - E0| " << drift << " J (" << bt.describe() << ")");
    return dq;
  };
  double to_bare = 0, drift_coarse = 0, drift_fine = 0;
  const double coarse = run(2e-3, to_bare, drift_coarse), fine = run(1e-3, to_bare, drift_fine);
  CHECK(fine < 0.75 * coarse);
  CHECK(fine < 0.1 * to_bare);
  CHECK(drift_fine < 0.75 * drift_coarse);
}
