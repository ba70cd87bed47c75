// The unicycle (tests/physics/bullet/unicycle_description.h) in Bullet, both rolling models
// (BulletHints::rolling), against the hand engine (ConstrainedMechanism<Spatial>, RK4) and the
// friction cone:
//  * From rest under constant torques (both models; friction grips there): x, y, φ, θ' and the contact
//    force agree to first order in dt, each within its predicted first-order term, halving with dt;
//    NoSlip's states never slip (its rows hold at the predicted end of the step).
//  * Friction on a circle: below μ m g it grips (the contact's slip ~1e-12 m/s), above it skids;
//    ramping the steer rate, the slip appears within a step or two of where the hand model's skid
//    margin μ f_n − |f_t| crosses zero, and |f_t| never exceeds μ f_n.
//  * The 1e-9 × stand-in masses of massless carriers do not matter: carriers of 1e-6 × m move the
//    run by far less than the tolerances.
// A bench line (MESSAGE, no timed assertion) gives µs/step for both models at dt 1 ms.
#include <doctest/doctest.h>

#include <chrono>
#include <cmath>
#include <string>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "tests/physics/bullet/unicycle_description.h"

using namespace dyn;
using dyn::bullet::BulletMechanism;
namespace t = dyn::bullet::test;

namespace {

// Lateral and longitudinal components of a world force in the wheel's axes at heading φ.
double lateral(const Spatial::Vec& f, double phi) { return -std::sin(phi) * f[3] + std::cos(phi) * f[4]; }
double longitudinal(const Spatial::Vec& f, double phi) { return std::cos(phi) * f[3] + std::sin(phi) * f[4]; }

constexpr double kTauY = 0.05, kTauZ = 0.002, kT = 2.0, kPhi0 = 0.3;

struct Agreement {
  double xy = 0, phi = 0, theta_rate = 0, f_lat = 0, f_long = 0, f_normal = 0, slip = 0, moment = 0, z = 0;
};

// From rest at heading 0.3 under τ_y = 0.05, τ_z = 0.002 for 2 s: Bullet NoSlip against the hand
// engine, worst over the run. Bullet's force is an impulse over a step: it is compared with the mean
// of the hand's forces at the step's two ends.
Agreement fromRest(double dt, const t::Unicycle& u = {}, RollingModel rolling = RollingModel::NoSlip,
                   const t::Unicycle& described = {}) {
  const MechanismModel<Spatial> model = u.model(rolling);
  ConstrainedMechanism<Spatial> hand(described.model());
  VecN q, v, qb, vb;
  u.state(kPhi0, 0, 0, q, v);
  BulletMechanism<Spatial> bullet(model, dt, q, v);
  VecN tau = VecN::Zero(5);
  tau[3] = kTauZ;
  tau[4] = kTauY;
  StepOptions o;
  o.dt = dt;
  Agreement a;
  Spatial::Vec f0 = hand.constraintForce(0, hand.solve(q, v, tau));
  for (long i = 0; i < std::lround(kT / dt); ++i) {
    REQUIRE(step(hand, o, tau, q, v));
    const Spatial::Vec f1 = hand.constraintForce(0, hand.solve(q, v, tau));
    bullet.step(tau);
    bullet.state(qb, vb);
    const Spatial::Vec fb = bullet.constraintForce(0), fh = 0.5 * (f0 + f1);
    f0 = f1;
    a.xy = std::max(a.xy, std::hypot(qb[0] - q[0], qb[1] - q[1]));
    a.phi = std::max(a.phi, std::abs(qb[3] - q[3]));
    a.theta_rate = std::max(a.theta_rate, std::abs(vb[4] - v[4]));
    a.f_lat = std::max(a.f_lat, std::abs(lateral(fb, qb[3]) - lateral(fh, q[3])));
    a.f_long = std::max(a.f_long, std::abs(longitudinal(fb, qb[3]) - longitudinal(fh, q[3])));
    a.f_normal = std::max(a.f_normal, std::abs(fb[5] - u.m * u.g));
    a.slip = std::max(a.slip, u.slip(qb, vb));
    a.z = std::max(a.z, std::abs(qb[2] - u.r));
    a.moment = std::max(a.moment, fb.head<3>().norm());
  }
  return a;
}

}  // namespace

TEST_CASE("unicycle: from rest under constant torques Bullet agrees with the hand engine to first order") {
  const t::Unicycle u;
  // The first-order terms of Bullet's semi-implicit Euler step, with θ'' = τ_y/(I_a + m r²), φ'' = τ_z/I_z:
  //  φ    lags by φ'' T dt / 2 (x_{n+1} = x_n + dt v_{n+1} under constant acceleration);
  //  θ'   loses (m r²/(I_a + m r²)) θ'' φ''² T⁴ dt / 8: each step turns the heading by φ' dt and the
  //       rows keep only the cos(φ' dt) part of the velocity along the new heading;
  //  x, y the along-track lag r θ'' T dt / 2 and the heading lag integrated, r θ'' φ'' T³ dt / 6.
  const double th_dd = kTauY / (u.Ia() + u.m * u.r * u.r), ph_dd = kTauZ / u.Id();
  for (RollingModel model : {RollingModel::NoSlip, RollingModel::Friction}) {
    const bool noslip = model == RollingModel::NoSlip;
    const Agreement a1 = fromRest(1e-3, u, model), a2 = fromRest(5e-4, u, model);
    for (const auto& [a, dt] : {std::pair{a1, 1e-3}, std::pair{a2, 5e-4}}) {
      MESSAGE(std::string(noslip ? "NoSlip" : "Friction") << ", dt " << dt * 1e3 << " ms: |Δxy| " << a.xy << " m, |Δφ| " << a.phi
                                               << " rad, |Δθ'| " << a.theta_rate << " rad/s, |Δf_lat| " << a.f_lat
                                               << " N, |Δf_long| " << a.f_long << " N, |f_n − m g| " << a.f_normal
                                               << " N, slip at Bullet's states " << a.slip << " m/s");
      const double phi_lag = ph_dd * kT * dt / 2;
      const double rate_loss = u.m * u.r * u.r / (u.Ia() + u.m * u.r * u.r) * th_dd * ph_dd * ph_dd * std::pow(kT, 4) * dt / 8;
      const double xy_lag = std::hypot(u.r * th_dd * kT * dt / 2, u.r * th_dd * ph_dd * std::pow(kT, 3) * dt / 6);
      CHECK(a.phi < 1.05 * phi_lag);
      CHECK(a.phi > 0.95 * phi_lag);  // it is that term, not an accident
      CHECK(a.theta_rate < 1.05 * rate_loss);
      CHECK(a.xy < 1.1 * xy_lag);
      // Forces: f_lat = m r θ' φ' carries those errors (m r (Δθ' φ' + θ' Δφ'): ~1e-4 N of 0.53 N at 1 ms);
      // the friction contact's rows act at the step's start geometry, the no-slip rows at its predicted
      // end: the friction force lags the hand's by a further step.
      CHECK(a.f_lat < (noslip ? 0.15 : 0.6) * dt);
      CHECK(a.f_long < (noslip ? 0.25 : 0.4) * dt);
      // The normal force holds the wheel and the two carriers below the z joint (2 × 2e-9 kg stand-ins).
      CHECK(a.f_normal < 1e-7);
      CHECK(a.moment < 1e-12);
      if (noslip) {
        CHECK(a.slip < 1e-12);  // rows at the predicted end of the step, where Bullet puts the wheel
      } else {
        // Rows at the step's start: at the new heading the state reads r θ' φ' dt (2.7e-4 m/s at
        // the end, 1 ms), while the contact itself holds (the grip tests below).
        const double lag = u.r * th_dd * ph_dd * kT * kT * dt;
        CHECK(a.slip < 1.01 * lag);
        CHECK(a.slip > 0.99 * lag);
      }
    }
    // First order: every error halves with dt.
    for (const auto& [e1, e2] : {std::pair{a1.xy, a2.xy}, std::pair{a1.phi, a2.phi},
                                 std::pair{a1.theta_rate, a2.theta_rate}, std::pair{a1.f_lat, a2.f_lat},
                                 std::pair{a1.f_long, a2.f_long}}) {
      CHECK(e1 / e2 > 1.8);
      CHECK(e1 / e2 < 2.2);
    }
  }
}

TEST_CASE("unicycle: a lopsided wheel (centre of mass off the disk, products of inertia) agrees alike") {
  // Bullet's wheel link then sits at the centre of mass on its principal axes, the disk's centre and
  // axle are carried into that frame, and the friction sphere sits off the link in a compound shape.
  t::Unicycle u;
  u.com_y = 0.03;
  u.product = 2e-3;
  for (RollingModel model : {RollingModel::NoSlip, RollingModel::Friction}) {
    const Agreement a1 = fromRest(1e-3, u, model, u), a2 = fromRest(5e-4, u, model, u);
    MESSAGE("lopsided, " << std::string(model == RollingModel::NoSlip ? "NoSlip" : "Friction") << ", dt 1 ms: |Δxy| "
                         << a1.xy << ", |Δφ| " << a1.phi << ", |Δθ'| " << a1.theta_rate << ", |Δf_lat| " << a1.f_lat
                         << ", |Δf_long| " << a1.f_long << ", |f_n − m g| " << a1.f_normal << ", moment " << a1.moment
                         << "; halving with dt: " << a1.xy / a2.xy << ", " << a1.phi / a2.phi << ", " << a1.theta_rate / a2.theta_rate
                         << ", " << a1.f_lat / a2.f_lat << ", " << a1.f_long / a2.f_long);
    // Livelier than the balanced wheel (the products of inertia turn spin into steer torque), so larger
    // first-order terms: bounds at 1.5 × the measured 1 ms values, and the halving below.
    CHECK(a1.xy < 2.5e-3);
    CHECK(a1.phi < 2.6e-2);
    CHECK(a1.theta_rate < 2.2e-2);
    CHECK(a1.f_lat < 3.3e-2);
    CHECK(a1.f_long < 1.2e-2);
    CHECK(a1.f_normal < 1e-7);
    CHECK(a1.moment < 1e-12);
    for (const auto& [e1, e2] : {std::pair{a1.xy, a2.xy}, std::pair{a1.phi, a2.phi}, std::pair{a1.theta_rate, a2.theta_rate},
                                 std::pair{a1.f_lat, a2.f_lat}, std::pair{a1.f_long, a2.f_long}}) {
      CHECK(e1 / e2 > 1.9);
      CHECK(e1 / e2 < 2.1);
    }
  }
}

// The largest difference between two Bullet NoSlip runs from rest (the fromRest torques, 2 s, dt 1 ms):
// in q, in θ' and in the lateral force.
struct Difference {
  double q = 0, theta_rate = 0, f_lat = 0;
};
Difference bulletDifference(const t::Unicycle& a, const t::Unicycle& b) {
  VecN q, v, qa, va, qb, vb;
  a.state(kPhi0, 0, 0, q, v);
  BulletMechanism<Spatial> A(a.model(), 1e-3, q, v), B(b.model(), 1e-3, q, v);
  VecN tau = VecN::Zero(5);
  tau[3] = kTauZ;
  tau[4] = kTauY;
  Difference d;
  for (int i = 0; i < 2000; ++i) {
    A.step(tau);
    B.step(tau);
    A.state(qa, va);
    B.state(qb, vb);
    d.q = std::max(d.q, (qa - qb).cwiseAbs().maxCoeff());
    d.theta_rate = std::max(d.theta_rate, std::abs(va[4] - vb[4]));
    d.f_lat = std::max(d.f_lat, std::abs(lateral(A.constraintForce(0), qa[3]) - lateral(B.constraintForce(0), qb[3])));
  }
  return d;
}

TEST_CASE("unicycle: the stand-in masses of massless carriers do not matter") {
  // The builder gives massless carriers 1e-9 × the wheel's mass and inertia. Carriers of 1e-6 and
  // 2e-6 × m move the run by an amount that doubles with them (linear), so the builder's own, 1000×
  // smaller, move it by a thousandth of that: far below the tolerances of the test above.
  const t::Unicycle none;
  t::Unicycle small = none, twice = none;
  small.carrier_mass = 1e-6 * none.m;
  twice.carrier_mass = 2e-6 * none.m;
  const Difference d1 = bulletDifference(none, small), d2 = bulletDifference(none, twice);
  MESSAGE("carriers of 1e-6 m: |Δq| " << d1.q << ", |Δθ'| " << d1.theta_rate << ", |Δf_lat| " << d1.f_lat
                                      << "; of 2e-6 m: " << d2.q << ", " << d2.theta_rate << ", " << d2.f_lat);
  CHECK(d1.q > 0);  // they do act
  for (const auto& [e1, e2] : {std::pair{d1.q, d2.q}, std::pair{d1.theta_rate, d2.theta_rate}, std::pair{d1.f_lat, d2.f_lat}}) {
    CHECK(e2 / e1 > 1.9);
    CHECK(e2 / e1 < 2.1);
  }
  // The builder's stand-ins: 1e-3 × d1, against the 1 ms tolerances (~1e-4 rad, rad/s, N).
  CHECK(1e-3 * d1.q < 1e-6 * 1e-4 * 1e3);
  CHECK(1e-3 * d1.theta_rate < 1e-6 * 1e-4 * 1e3);
  CHECK(1e-3 * d1.f_lat < 1e-6 * 1e-4 * 1e3);
}

namespace {

// The contact's own slip over the last step: the wheel's material velocity at the contact Bullet
// solved for (the step's start geometry, heading φ_start) with the velocities it produced. Measured at
// the new heading instead it reads v φ' dt more: the rows hold where the wheel was.
double contactSlip(const t::Unicycle& u, double phi_start, const VecN& q, const VecN& v) {
  VecN at = q;
  at[3] = phi_start;
  return u.slip(at, v);
}

struct Circle {
  double worst_slip = 0, final_slip = 0, worst_cone = 0, normal_error = 0;
};

// Friction model on a circle at 1 m/s (θ' = 10 rad/s) turning at φ', no torque, 0.3 s.
Circle circle(double phi_rate, double dt) {
  const t::Unicycle u;
  VecN q, v;
  u.state(0.0, 10.0, phi_rate, q, v);
  BulletMechanism<Spatial> bullet(u.model(RollingModel::Friction), dt, q, v);
  Circle c;
  for (long i = 0; i < std::lround(0.3 / dt); ++i) {
    const double phi = q[3];
    bullet.step(VecN::Zero(5));
    bullet.state(q, v);
    const Spatial::Vec f = bullet.constraintForce(0);
    c.final_slip = contactSlip(u, phi, q, v);
    c.worst_slip = std::max(c.worst_slip, c.final_slip);
    c.worst_cone = std::max(c.worst_cone, std::hypot(f[3], f[4]) / (u.mu * f[5]));
    c.normal_error = std::max(c.normal_error, std::abs(f[5] - u.m * u.g));
  }
  return c;
}

}  // namespace

TEST_CASE("unicycle, Friction: grips while m v φ' < μ m g, skids above") {
  const t::Unicycle u;
  const double limit = u.mu * u.g / 1.0;  // φ' at which m v φ' = μ m g, v = 1 m/s: 7.85 rad/s
  const Circle grip = circle(0.5 * limit, 1e-3), near = circle(0.9 * limit, 1e-3), skid = circle(1.5 * limit, 1e-3);
  MESSAGE("grip (m v φ' = 0.5 μ m g): contact slip " << grip.worst_slip << " m/s, |f_t|/(μ f_n) ≤ " << grip.worst_cone);
  MESSAGE("near (0.9 μ m g): contact slip " << near.worst_slip << " m/s, |f_t|/(μ f_n) ≤ " << near.worst_cone);
  MESSAGE("skid (1.5 μ m g): contact slip up to " << skid.worst_slip << " m/s, |f_t|/(μ f_n) ≤ " << skid.worst_cone);
  CHECK(grip.worst_slip < 1e-9);
  CHECK(near.worst_slip < 1e-9);
  CHECK(std::abs(grip.worst_cone - 0.5) < 1e-3);  // the friction force is the centripetal m v φ'
  CHECK(std::abs(near.worst_cone - 0.9) < 1e-3);
  CHECK(grip.normal_error < 1e-6);
  CHECK(skid.worst_slip > 0.1);                   // clearly sliding
  CHECK(skid.worst_cone < 1 + 1e-9);              // on the cone, never outside it
  CHECK(skid.worst_cone > 1 - 1e-9);
}

TEST_CASE("unicycle, Friction: ramping the steer rate, the slip appears where the no-slip force leaves the cone") {
  // From φ' = 7 rad/s at 1 m/s, τ_z = 0.05 N·m ramps φ' at 10 rad/s² (the contact force has no moment
  // about the steering axis, so φ' ramps alike in both engines): the hand model's lateral force
  // m r θ' φ' crosses μ m g = 15.7 N after ~85 ms, rising 0.02 N per ms.
  const t::Unicycle u;
  for (double dt : {1e-3, 5e-4}) {
    VecN q, v, qh, vh;
    u.state(0.0, 10.0, 7.0, q, v);
    qh = q, vh = v;
    ConstrainedMechanism<Spatial> hand(u.model());
    BulletMechanism<Spatial> bullet(u.model(RollingModel::Friction), dt, q, v);
    VecN tau = VecN::Zero(5);
    tau[3] = 0.05;
    StepOptions o;
    o.dt = dt;
    long cross = -1, onset = -1, saturated = -1;
    double slip = 0, worst_cone = 0;
    const long steps = std::lround(0.2 / dt);
    for (long i = 0; i < steps; ++i) {
      // Hand: the skid margin μ f_n − |f_t| over this step (mean of its ends).
      double r0[5], r1[5];
      hand.constraintReport(0, hand.solve(qh, vh, tau), r0);
      REQUIRE(step(hand, o, tau, qh, vh));
      hand.constraintReport(0, hand.solve(qh, vh, tau), r1);
      if (cross < 0 && 0.5 * (r0[3] + r1[3]) < 0) cross = i;
      const double phi = q[3];
      bullet.step(tau);
      bullet.state(q, v);
      const Spatial::Vec f = bullet.constraintForce(0);
      const double cone = std::hypot(f[3], f[4]) / (u.mu * f[5]);
      worst_cone = std::max(worst_cone, cone);
      if (saturated < 0 && cone > 1 - 1e-9) saturated = i;
      slip = contactSlip(u, phi, q, v);
      if (onset < 0 && slip > 1e-6) onset = i;
      if (cross < 0 || i < cross - 2) CHECK(slip < 1e-9);  // gripping up to the crossing
    }
    MESSAGE("dt " << dt * 1e3 << " ms: hand's margin crosses 0 in step " << cross << " (t = " << cross * dt
                  << " s); Bullet's friction reaches μ f_n in step " << saturated << ", its contact slips (> 1e-6 m/s) from step " << onset << "; slip " << slip << " m/s at t = 0.2 s");
    REQUIRE(cross > 0);
    // Bullet's friction rows act at the step's start geometry, so its lateral force over a step is the
    // demand of the step before (1–2 steps behind the hand's, whose margin is the mean over a step).
    CHECK(saturated >= cross);
    CHECK(saturated - cross <= 2);
    CHECK(onset >= saturated);
    CHECK(onset - cross <= 3);
    CHECK(slip > 1e-2);
    CHECK(worst_cone < 1 + 1e-9);
  }
}

TEST_CASE("unicycle: µs per Bullet step at dt 1 ms (bench line, no assertion on time)") {
  const t::Unicycle u;
  VecN tau = VecN::Zero(5);
  tau[3] = kTauZ;
  tau[4] = kTauY;
  for (RollingModel m : {RollingModel::NoSlip, RollingModel::Friction}) {
    VecN q, v;
    u.state(0.0, 10.0, 2.0, q, v);
    BulletMechanism<Spatial> bullet(u.model(m), 1e-3, q, v);
    const int steps = 3000;
    const auto t0 = std::chrono::steady_clock::now();
    for (int i = 0; i < steps; ++i) bullet.step(tau);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / steps;
    MESSAGE(bullet.describe() << ": " << us << " µs/step");
    bullet.state(q, v);
    CHECK(q.allFinite());
  }
  ConstrainedMechanism<Spatial> hand(u.model());
  VecN q, v;
  u.state(0.0, 10.0, 2.0, q, v);
  StepOptions o;
  const int steps = 3000;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < steps; ++i) REQUIRE(step(hand, o, tau, q, v));
  MESSAGE("hand (RK4 + projection, dynamic sizes): "
          << std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() / steps << " µs/step");
}


TEST_CASE("unicycle: Bullet runs are deterministic (same input, same bytes)") {
  const t::Unicycle u;
  for (RollingModel m : {RollingModel::NoSlip, RollingModel::Friction}) {
    VecN q, v;
    u.state(0.0, 10.0, 12.0, q, v);  // the friction wheel skids
    BulletMechanism<Spatial> a(u.model(m), 1e-3, q, v), b(u.model(m), 1e-3, q, v);
    VecN tau = VecN::Zero(5);
    tau[4] = 0.1;
    for (int i = 0; i < 200; ++i) {
      a.step(tau);
      b.step(tau);
    }
    VecN qa, va, qb, vb;
    a.state(qa, va);
    b.state(qb, vb);
    CHECK(qa == qb);
    CHECK(va == vb);
    CHECK(a.constraintForce(0) == b.constraintForce(0));
  }
}
