// External forces in the Bullet builder (physics/bullet/bullet_mechanism.cpp): the description's push on
// a link point and on a payload, applied by Bullet at each of its steps from the state at the step's
// start, against the hand engine's RK4 (the force at every stage) at dt/8:
//  * the pushed arm's gap falls at first order (Bullet's step), 1e-2 rad class at dt 1 ms over 0.5 s;
//  * a pushed free body (no gravity) is the closed form x = x0 + F t²/(2m) to Bullet's first order;
//  * Bullet's books: W of a constant push is F·Δp of its own motion (held force × displacement).
#include <doctest/doctest.h>

#include <cmath>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/forces.h"
#include "tests/physics/arms.h"

using namespace dyn;

namespace {

using Pos = Planar::Pos;
const Pos kTip(0.2, 0.0);
const Planar::Vec kPush(0.0, 6.0, -4.0);

MechanismModel<Planar> pushedArm() {
  MechanismModel<Planar> d;
  d.tree = test::planarArm();
  d.forces.push_back(std::make_shared<PushForce<Planar>>(BodyRef::link(2), kTip, kPush, ForceProfile{}));
  return d;
}

VecN startAngles() { return (VecN(3) << 0.3, -0.8, 0.5).finished(); }

VecN bulletRun(const MechanismModel<Planar>& d, double dt, double T, const VecN& q0, Books* books = nullptr) {
  bullet::BulletMechanism<Planar> b(d, dt, q0, VecN::Zero(q0.size()));
  const VecN tau = VecN::Zero(d.treeDof());
  for (long k = 0; k < std::lround(T / dt); ++k) b.step(tau, double(k) * dt);
  VecN q, v;
  b.state(q, v);
  if (books) *books = b.books();
  return q;
}

VecN handRun(const MechanismModel<Planar>& d, double dt, double T, const VecN& q0) {
  ConstrainedMechanism<Planar> mech(d);
  StepOptions o;
  o.dt = dt;
  o.drift.kind = Drift::None;
  VecN q = q0, v = VecN::Zero(q0.size());
  const VecN tau = VecN::Zero(d.treeDof());
  for (long k = 0; k < std::lround(T / dt); ++k) REQUIRE(step(mech, o, tau, q, v));
  return q;
}

}  // namespace

TEST_CASE("Bullet applies the description's push on a link point: first order against the hand engine") {
  const double T = 0.5;
  const VecN ref = handRun(pushedArm(), 1.25e-4, T, startAngles());
  const double coarse = (bulletRun(pushedArm(), 1e-3, T, startAngles()) - ref).lpNorm<Eigen::Infinity>();
  const double fine = (bulletRun(pushedArm(), 5e-4, T, startAngles()) - ref).lpNorm<Eigen::Infinity>();
  MESSAGE("Bullet |q − q_hand| at dt 1 ms " << coarse << " rad, 0.5 ms " << fine << " rad");
  CHECK(coarse < 1e-2);
  CHECK(coarse / fine == doctest::Approx(2.0).epsilon(0.25));  // first order
  // Without the push the arm ends far from the pushed one: the push is applied at all.
  MechanismModel<Planar> free;
  free.tree = test::planarArm();
  CHECK((bulletRun(free, 1e-3, T, startAngles()) - ref).lpNorm<Eigen::Infinity>() > 20 * coarse);
}

TEST_CASE("Bullet pushes a free payload as F t²/(2m), and its books hold the push's work F·Δx") {
  MechanismModel<Planar> d;
  d.tree.gravity.setZero();
  Payload box;
  box.mass = 2.0, box.inertia = 0.01;
  d.payloads.push_back(box);
  const Planar::Vec F(0.0, 3.0, -1.0);
  d.forces.push_back(std::make_shared<PushForce<Planar>>(BodyRef::payload(0), Pos::Zero(), F, ForceProfile{}));
  const VecN q0 = VecN::Zero(3);
  Books books;
  const double dt = 1e-3, T = 1.0;
  const VecN q = bulletRun(d, dt, T, q0, &books);
  // Semi-implicit Euler under a constant force: x_N = F dt² N (N + 1)/(2m), exactly.
  const double N = T / dt, expect_x = F[1] * dt * dt * N * (N + 1) / (2 * box.mass), expect_y = F[2] * dt * dt * N * (N + 1) / (2 * box.mass);
  CHECK(q[1] == doctest::Approx(expect_x).epsilon(1e-9));
  CHECK(q[2] == doctest::Approx(expect_y).epsilon(1e-9));
  CHECK(std::abs(q[0]) < 1e-12);  // a force at the centre of mass turns nothing
  CHECK(books.work == doctest::Approx(F[1] * q[1] + F[2] * q[2]).epsilon(1e-9));
}
