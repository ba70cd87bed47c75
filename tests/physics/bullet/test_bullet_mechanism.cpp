// Tests of the Bullet builder (physics/bullet/bullet_mechanism.h) against the hand-made Bullet slider
// crank, closed forms (pendulum period, damped spring frequency, free fall) and itself (cut vs uncut).
#include "physics/bullet/bullet_mechanism.h"

#include <doctest/doctest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "physics/bullet/slider_crank_bullet.h"
#include "tests/physics/bullet/slider_crank_description.h"

using dyn::BodyRef;
using dyn::JointType;
using dyn::MechanismModel;
using dyn::Planar;
using dyn::VecN;
using dyn::bullet::BulletMechanism;
using Eigen::Vector2d;
using Eigen::Vector3d;
namespace t = dyn::bullet::test;

namespace {

constexpr double kPi = std::numbers::pi;

// The slider-crank parameters of test_slider_crank_bullet.cpp, in both models' structs.
t::SliderCrankModel crankParams(double th1_deg = 45.0) {
  t::SliderCrankModel m;
  const double l[3] = {0.5, 0.4, 0.3}, mass[3] = {1.0, 0.8, 0.5};
  for (int i = 0; i < 3; ++i) m.links[std::size_t(i)] = {l[i], mass[i], mass[i] * l[i] * l[i] / 12.0, Vector2d(l[i] / 2, 0)};
  m.load_mass = 0.5;
  m.gravity = {0.0, -9.81};
  const double t1 = th1_deg * kPi / 180.0;
  const double a12 = std::asin(-l[0] * std::sin(t1) / l[1]);
  m.q0 = {t1, a12 - t1, -a12};
  m.qd0.setZero();
  return m;
}
dyn::bullet::SliderCrankModel handMade(const t::SliderCrankModel& p) {
  dyn::bullet::SliderCrankModel m;
  for (int i = 0; i < 3; ++i) {
    const auto& l = p.links[std::size_t(i)];
    m.links[std::size_t(i)] = {l.length, l.mass, l.inertia, l.com};
  }
  m.load_mass = p.load_mass, m.gravity = p.gravity, m.q0 = p.q0, m.qd0 = p.qd0;
  return m;
}

// Largest differences between the described and the hand-made model over a run.
struct Gap {
  double q = 0, qd = 0, x = 0, v = 0, f = 0, fmax = 0;
};
template <class Torque>
Gap compareCrank(double dt, int steps, Torque tau_of) {
  const t::SliderCrankModel p = crankParams();
  dyn::bullet::SliderCrankBullet ref(handMade(p), dt);
  t::SliderCrankMechanism mech(p, dt);
  Gap g;
  for (int k = 0; k < steps; ++k) {
    const Vector3d tau = tau_of(ref.time());
    ref.step(tau);
    mech.step(tau);
    g.q = std::max(g.q, (mech.q() - ref.q()).cwiseAbs().maxCoeff());
    g.qd = std::max(g.qd, (mech.qd() - ref.qd()).cwiseAbs().maxCoeff());
    g.x = std::max(g.x, std::abs(mech.x_c() - ref.x_c()));
    g.v = std::max(g.v, std::abs(mech.v_c() - ref.v_c()));
    g.f = std::max(g.f, (mech.tipForce() - ref.tipForce()).cwiseAbs().maxCoeff());
    g.fmax = std::max(g.fmax, ref.tipForce().cwiseAbs().maxCoeff());
  }
  return g;
}

}  // namespace

TEST_CASE("slider crank from its description equals the hand-made Bullet model") {
  const t::SliderCrankModel p = crankParams();
  t::SliderCrankMechanism mech(p, 1e-3);
  MESSAGE(mech.mechanism().describe());
  CHECK(mech.mechanism().describe() == "Bullet 3.24 btMultiBody (4 links) grown from the world, cut at joint 1, "
                                       "1 weld(s) as fixed joints, PGS 30 iterations");
  // Same Bullet tree, settings and step: only the read-outs' rounding differs (measured below).
  const Gap passive = compareCrank(1e-3, 2000, [](double) { return Vector3d::Zero(); });
  const Gap driven = compareCrank(1e-3, 2000, [](double s) {
    return Vector3d(2.0 * std::sin(3 * s), -1.5 * std::cos(2 * s), 0.8 * std::sin(5 * s));
  });
  for (const Gap& g : {passive, driven}) {
    MESSAGE("max gaps: q " << g.q << ", q' " << g.qd << ", x_c " << g.x << ", v_c " << g.v << ", f_T " << g.f
                           << " (|f_T| up to " << g.fmax << " N)");
    CHECK(g.q < 1e-12);
    CHECK(g.qd < 1e-11);
    CHECK(g.x < 1e-12);
    CHECK(g.v < 1e-11);
    CHECK(g.f < 1e-9 * g.fmax);
  }
}
