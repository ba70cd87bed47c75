// BulletMechanism<Spatial> on a general spatial description (physics/bullet/spatial_mechanism.cpp):
//  * two trees hung from the world with rotated placements X_tree, tilted revolute and prismatic axes,
//    centres of mass off the joints, full (non-diagonal) inertias, a massless body and joint
//    properties. Bullet's first step is v₁ = v₀ + dt a(q₀, v₀) (semi-implicit Euler), so its
//    (v₁ − v₀)/dt must be the hand engine's forward dynamics at (q₀, v₀) to rounding: a check of every
//    convention of the link mapping at once, independent of dt. Over 0.5 s the two then agree to
//    first order in dt.
//  * descriptions it cannot model throw std::invalid_argument saying what.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/constraints/point_closure.h"
#include "physics/constraints/point_contact.h"
#include "tests/physics/bullet/unicycle_description.h"

using namespace dyn;
using dyn::bullet::BulletMechanism;
using Pos = Spatial::Pos;
using Mat3 = Eigen::Matrix3d;

namespace {

Spatial::Transform placement(double angle, const Pos& axis, const Pos& at) {
  return {Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix().transpose(), at};
}

// A symmetric positive-definite inertia about the centre of mass with products of inertia.
Mat3 fullInertia(double a, double b, double c, double p) {
  Mat3 I;
  I << a, p, -0.5 * p, p, b, 0.3 * p, -0.5 * p, 0.3 * p, c;
  return I;
}

// Tree A (3 bodies): revolute → prismatic → revolute; tree B (3 bodies): revolute → massless revolute
// → revolute. Gravity −z; a spring on the prismatic joint, viscous friction on joint 0.
MechanismModel<Spatial> twoTrees() {
  MechanismModel<Spatial> m;
  auto& t = m.tree;
  t.gravity << 0, 0, 0, 0, 0, -9.81;
  int a = t.addBody(-1, JointType::Revolute, Pos(0, 0, 1), placement(0.4, Pos(0.3, -0.5, 0.8), Pos(0.1, -0.05, 0.2)),
                    Spatial::inertia(1.2, Pos(0.15, 0.02, -0.05), fullInertia(0.02, 0.03, 0.025, 0.004)));
  a = t.addBody(a, JointType::Prismatic, Pos(0.2, 1, 0.1), placement(-0.7, Pos(1, 0.2, 0), Pos(0.3, 0, 0)),
                Spatial::inertia(0.7, Pos(0, 0.1, 0.05), fullInertia(0.01, 0.006, 0.012, -0.002)));
  t.addBody(a, JointType::Revolute, Pos(1, 0, 0.3), placement(0.9, Pos(0, 0, 1), Pos(0, 0.25, 0)),
            Spatial::inertia(0.5, Pos(0.2, 0, 0), fullInertia(0.002, 0.008, 0.008, 0.001)));
  int b = t.addBody(-1, JointType::Revolute, Pos(0, 0, 1), placement(1.2, Pos(1, 0, 0), Pos(-0.4, 0, 0)),
                    Spatial::inertia(1.0, Pos(0.2, 0, 0), Eigen::Vector3d(0.004, 0.02, 0.02).asDiagonal()));
  b = t.addBody(b, JointType::Revolute, Pos(0, 1, 0), Spatial::translation(Pos(0.4, 0, 0)), Spatial::Mat::Zero());
  t.addBody(b, JointType::Revolute, Pos(1, 0, 0), placement(0.3, Pos(0, 1, 0), Pos(0.05, 0, 0)),
            Spatial::inertia(0.3, Pos(0, 0, -0.2), Eigen::Vector3d(0.004, 0.004, 0.001).asDiagonal()));
  m.joints.assign(6, JointProperties{});
  m.joints[1].stiffness = 20.0;
  m.joints[1].rest = 0.05;
  m.joints[0].viscous = 0.1;
  return m;
}

void initial(VecN& q, VecN& v) {
  q.resize(6);
  v.resize(6);
  q << 0.3, 0.1, -0.5, 0.8, 0.6, -0.4;
  v << 0.5, -0.2, 1.0, -0.5, 1.0, 0.3;
}

// Hand RK4 (no constraints) against Bullet over 0.3 s: worst |Δq|, |Δv|.
std::pair<double, double> swing(double dt) {
  const MechanismModel<Spatial> model = twoTrees();
  ConstrainedMechanism<Spatial> hand(model);
  VecN q, v, qb, vb;
  initial(q, v);
  BulletMechanism<Spatial> bullet(model, dt, q, v);
  StepOptions o;
  o.dt = dt;
  const VecN tau = (VecN(6) << 0.05, -0.5, 0.0, 0.1, 0.02, -0.01).finished();
  double dq = 0, dv = 0;
  for (long i = 0; i < std::lround(0.3 / dt); ++i) {
    REQUIRE(step(hand, o, tau, q, v));
    bullet.step(tau);
    bullet.state(qb, vb);
    dq = std::max(dq, (qb - q).cwiseAbs().maxCoeff());
    dv = std::max(dv, (vb - v).cwiseAbs().maxCoeff());
  }
  return {dq, dv};
}

std::string thrown(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(nothing thrown)";
}

}  // namespace

TEST_CASE("spatial trees: Bullet's first step is the hand engine's forward dynamics, to rounding") {
  const MechanismModel<Spatial> model = twoTrees();
  ConstrainedMechanism<Spatial> hand(model);
  VecN q, v;
  initial(q, v);
  const VecN tau = (VecN(6) << 0.05, -0.5, 0.0, 0.1, 0.02, -0.01).finished();
  const VecN a = hand.solve(q, v, tau).qdd;
  const double dt = 1e-3;
  BulletMechanism<Spatial> bullet(model, dt, q, v);
  bullet.step(tau);
  VecN q1, v1;
  bullet.state(q1, v1);
  const VecN a_bullet = (v1 - v) / dt;
  MESSAGE("hand θ'' " << a.transpose() << "\nBullet    " << a_bullet.transpose() << "\nworst difference "
                     << (a_bullet - a).cwiseAbs().maxCoeff());
  // What is left (3e-10 of |θ''|) is the massless body's 1e-9 stand-in mass: it scales with it (a
  // stand-in of 1e-12 leaves 3e-13).
  CHECK((a_bullet - a).cwiseAbs().maxCoeff() < 2e-9 * a.cwiseAbs().maxCoeff());
  CHECK((q1 - (q + dt * v1)).cwiseAbs().maxCoeff() < 1e-12);  // x₁ = x₀ + dt v₁
  CHECK(bullet.describe().find("6 links") != std::string::npos);
}

TEST_CASE("spatial trees: hand and Bullet agree to first order in dt") {
  const auto [dq1, dv1] = swing(1e-3);
  const auto [dq2, dv2] = swing(5e-4);
  MESSAGE("dt 1 ms: |Δq| " << dq1 << ", |Δv| " << dv1 << "; dt 0.5 ms: " << dq2 << ", " << dv2);
  // A lively motion (θ'' up to 60 rad/s²): Bullet's first-order step is 4e-3 rad and 0.1 rad/s off
  // after 0.3 s at 1 ms, halving with dt.
  CHECK(dq1 < 6e-3);
  CHECK(dv1 < 0.15);
  CHECK(dq1 / dq2 > 1.8);
  CHECK(dq1 / dq2 < 2.2);
  CHECK(dv1 / dv2 > 1.8);
  CHECK(dv1 / dv2 < 2.2);
}

TEST_CASE("spatial: descriptions Bullet cannot model throw std::invalid_argument naming what") {
  const dyn::bullet::test::Unicycle u;
  VecN q, v;
  u.state(0, 0, 0, q, v);
  {
    auto m = u.model();
    m.payloads.push_back(Payload{});
    CHECK(thrown([&] { BulletMechanism<Spatial>(m, 1e-3, q, v); }).find("spatial payloads: not yet") != std::string::npos);
  }
  {
    auto m = u.model();
    m.constraints.push_back(std::make_shared<PointContact<Spatial>>(BodyRef::link(4), Pos::Zero(), BodyRef::world(),
                                                                    Pos(0, 0, 0.1), Pos(0, 0, 1), 0.5));
    const std::string what = thrown([&] { BulletMechanism<Spatial>(m, 1e-3, q, v); });
    CHECK(what.find("constraint 1 (point_contact): not yet") != std::string::npos);
  }
  {
    auto m = u.model();
    m.bullet.cut_joints = {3};
    CHECK(thrown([&] { BulletMechanism<Spatial>(m, 1e-3, q, v); }).find("cut joints: not yet") != std::string::npos);
  }
  CHECK(thrown([&] { BulletMechanism<Spatial>(u.model(), 1e-3, VecN::Zero(3), v); }).find("need 5 coordinates") != std::string::npos);
  CHECK(thrown([&] { BulletMechanism<Spatial>(u.model(), 0.0, q, v); }).find("dt") != std::string::npos);
  BulletMechanism<Spatial> ok(u.model(), 1e-3, q, v);
  CHECK(thrown([&] { ok.step(VecN::Zero(4)); }).find("one value per tree joint") != std::string::npos);
  CHECK_THROWS_AS(ok.constraintForce(1), std::out_of_range);
}
