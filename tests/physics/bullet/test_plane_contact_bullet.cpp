// plane_contact in Bullet (physics/bullet/contact_balls.h, both builders), against closed forms and
// invariants (dt 1 ms unless said; every check holds at 0.25 ms too where both are run):
//  * a ball dropped from H (ρ = 0: Bullet's 1 mm stand-in, and ρ = 2 cm) touches down at the end of the
//    step in which free fall reaches the table (within 2 dt of √(2H/g)); Bullet's contact is
//    speculative, so it stops exactly on the plane: no bounce, no sinking (gap, speed 0 to 1e-12); at
//    rest η = m g to rounding, and Σ η dt = m g T (momentum);
//  * any unit normal: on a tilted frictionless plane the ball slides as the discrete step of g sin α
//    predicts (½ a T (T + dt), to 1e-9) pressing with m g cos α; pushed by F against a wall (horizontal
//    n) it falls freely pressing with F;
//  * compliant (k_e, d_e): the resting depth is m g / k_e to 1e-9 (Bullet's erp/cfm rows rest exactly
//    at f = k d); critically damped, the sinking follows the closed form within 0.2 ω dt × m g / k_e
//    (first order: it halves with dt); undamped, Bullet's implicit step damps the bounce by about
//    exp(−π ω dt) a period — a numerical damping ratio ω dt / 2 the hand model does not have;
//  * friction μ: a push below μ f_n is held (speed 0, friction = −push), above it slides at
//    (F − μ m g)/m with friction μ f_n;
//  * the pen-on-table arm resting its tip: frictionless with τ = G − Jᵀ n η_d it stays and presses with
//    η_d; with μ = 1 and τ = G/2 the pinned arm is a structure and the table's force is J_Pᵀ⁻¹ (G − τ)
//    (J_P the Jacobian of the contact point, ρ below the tip: friction acts there); both to 1e-8, also
//    with products of inertia on the tip link (Bullet turns it onto principal axes, the ball with it);
//  * lift-off: torques that pull the tip up give η = 0 from the first step and a gap growing as the
//    free arm's ½ a_n T (T + dt) (1 %);
//  * two balls on one link share the weight by the lever rule; the planar builder: a disk (tree or
//    payload) dropped on a floor, pressed on a tilted wall, held by friction and sinking into a
//    compliant floor, and a contact inside the subtree of a weld-made fixed joint (slider crank): the
//    weld's force still obeys the slider's Newton equation;
//  * descriptions Bullet cannot model are refused naming what; runs are deterministic to the byte.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "physics/bullet/bullet_mechanism.h"
#include "tests/physics/bullet/plane_contact_description.h"
#include "tests/physics/bullet/slider_crank_description.h"

using namespace dyn;
using dyn::bullet::BulletMechanism;
namespace t = dyn::bullet::test;
using Pos = Spatial::Pos;

namespace {

constexpr double kPi = 3.14159265358979323846;

// A ball dropped from rest, its lowest point H above the table.
struct Drop {
  double touchdown = -1;  // end of the first step with η > 0
  double gap_after = 0;   // worst |gap| after touchdown
  double v_after = 0;     // worst |v_z| after touchdown
  double rest_eta = 0;    // η at the end
  double momentum = 0;    // Σ η dt
  double min_eta = 0;
};

Drop drop(double dt, double H, double radius, double T) {
  t::Ball b;
  b.params.radius = radius;
  b.params.height = 0.1;
  VecN q(3), v = VecN::Zero(3), qb, vb;
  q << 0.2, -0.1, b.params.height + radius + H;
  BulletMechanism<Spatial> bullet(b.model(), dt, q, v);
  Drop d;
  for (long i = 1; i <= std::lround(T / dt); ++i) {
    bullet.step(VecN::Zero(3));
    bullet.state(qb, vb);
    const double eta = bullet.constraintForce(0).tail<3>().dot(b.normal);
    if (d.touchdown >= 0) {
      d.gap_after = std::max(d.gap_after, std::abs(b.gap(qb)));
      d.v_after = std::max(d.v_after, vb.norm());
    } else if (eta > 0) {
      d.touchdown = double(i) * dt;
    }
    d.momentum += eta * dt;
    d.min_eta = std::min(d.min_eta, eta);
    d.rest_eta = eta;
  }
  return d;
}

// A ball set on a compliant table at gap 0 and rest, damping ratio ζ: its depth against the closed form
// of m d'' = m g − k d − c d' (ζ = 1: d = (m g/k)(1 − (1 + ω t) e^{−ω t}); ζ = 0: (m g/k)(1 − cos ω t)).
struct Sink {
  double w = 0;      // √(k/m)
  double rest = 0;   // depth at the end / (m g / k)
  double err = 0;    // worst |depth − closed form| / (m g / k)  (ζ = 1)
  double decay = 0;  // ζ = 0: (peak in the third period − 1) / (peak in the first − 1)
};

Sink sink(double k, double zeta, double dt, double T) {
  t::Ball b;
  b.params.stiffness = k;
  b.params.damping = 2 * zeta * std::sqrt(k * b.m);
  VecN q = VecN::Zero(3), v = VecN::Zero(3), qb, vb;
  BulletMechanism<Spatial> bullet(b.model(), dt, q, v);
  Sink s;
  s.w = std::sqrt(k / b.m);
  const double unit = b.m * b.g / k, period = 2 * kPi / s.w;
  double peak1 = 0, peak3 = 0;
  for (long i = 1; i <= std::lround(T / dt); ++i) {
    bullet.step(VecN::Zero(3));
    bullet.state(qb, vb);
    const double t = double(i) * dt, depth = -b.gap(qb) / unit;
    if (zeta > 0) s.err = std::max(s.err, std::abs(depth - (1 - (1 + s.w * t) * std::exp(-s.w * t))));
    if (t < period) peak1 = std::max(peak1, depth);
    if (t > 2 * period && t < 3 * period) peak3 = std::max(peak3, depth);
    s.rest = depth;
  }
  s.decay = (peak3 - 1) / (peak1 - 1);
  return s;
}

}  // namespace

TEST_CASE("plane_contact, Bullet: a dropped ball touches down on time, does not bounce, rests on its weight") {
  const t::Ball b;
  const double H = 0.05, T = 0.5;
  for (double radius : {0.0, 0.02})
    for (double dt : {1e-3, 2.5e-4}) {
      const Drop d = drop(dt, H, radius, T);
      const double t_fall = std::sqrt(2 * H / b.g);
      MESSAGE("ρ " << radius << ", dt " << dt << ": touchdown " << d.touchdown << " s (free fall " << t_fall << "), |gap| after "
                   << d.gap_after << ", |v| after " << d.v_after << ", η at rest " << d.rest_eta << " (m g " << b.m * b.g
                   << "), Σ η dt " << d.momentum << " (m g T " << b.m * b.g * T << "), min η " << d.min_eta);
      CHECK(d.touchdown >= t_fall - 1e-12);
      CHECK(d.touchdown <= t_fall + 2 * dt);
      CHECK(d.gap_after < 1e-12);
      CHECK(d.v_after < 1e-12);
      CHECK(d.rest_eta == doctest::Approx(b.m * b.g).epsilon(1e-9));
      CHECK(d.momentum == doctest::Approx(b.m * b.g * T).epsilon(1e-9));
      CHECK(d.min_eta >= 0.0);
    }
}

TEST_CASE("plane_contact, Bullet: any unit normal (tilted plane, wall)") {
  const double alpha = 0.3, dt = 1e-3, T = 0.3;
  VecN qb, vb;
  {
    t::Ball b;
    b.normal = Pos(std::sin(alpha), 0, std::cos(alpha));
    b.params.radius = 0.01;
    b.params.height = 0.05;
    VecN q = (VecN(3) << 0.1, 0.2, 0.0).finished(), v = VecN::Zero(3);
    q[2] = (b.params.height + b.params.radius - b.normal.x() * q[0]) / b.normal.z();  // gap 0
    const VecN q0 = q;
    BulletMechanism<Spatial> bullet(b.model(), dt, q, v);
    double worst_eta = 0, worst_gap = 0;
    for (long i = 1; i <= std::lround(T / dt); ++i) {
      bullet.step(VecN::Zero(3));
      bullet.state(qb, vb);
      worst_eta = std::max(worst_eta, std::abs(bullet.constraintForce(0).tail<3>().dot(b.normal) - b.m * b.g * std::cos(alpha)));
      worst_gap = std::max(worst_gap, std::abs(b.gap(qb)));
    }
    const Pos down(std::cos(alpha), 0, -std::sin(alpha));
    const double s = down.dot(Pos(qb[0] - q0[0], qb[1] - q0[1], qb[2] - q0[2]));
    const double s_step = 0.5 * b.g * std::sin(alpha) * T * (T + dt);  // semi-implicit Euler's k(k+1)/2 dt² a
    MESSAGE("tilted plane: slid " << s << " m (discrete " << s_step << ", ½ a T² " << 0.5 * b.g * std::sin(alpha) * T * T
                                  << "), worst |η − m g cos α| " << worst_eta << ", worst |gap| " << worst_gap);
    CHECK(s == doctest::Approx(s_step).epsilon(1e-9));
    CHECK(worst_eta < 1e-8);
    CHECK(worst_gap < 1e-12);
  }
  {
    t::Ball w;
    w.normal = Pos(std::cos(0.4), std::sin(0.4), 0);
    w.params.height = -0.2;
    VecN q(3), v = VecN::Zero(3);
    q << 0, 0, 1.0;
    q.head<2>() = (w.params.height + w.params.radius) * w.normal.head<2>();
    BulletMechanism<Spatial> wall(w.model(), dt, q, v);
    const double F = 3.0;
    VecN tau = VecN::Zero(3);
    tau.head<2>() = -F * w.normal.head<2>();
    double worst = 0;
    for (long i = 1; i <= std::lround(T / dt); ++i) {
      wall.step(tau);
      wall.state(qb, vb);
      worst = std::max(worst, std::abs(wall.constraintForce(0).tail<3>().dot(w.normal) - F));
    }
    const double fell = 0.5 * w.g * T * (T + dt);
    MESSAGE("wall: worst |η − F| " << worst << ", gap " << w.gap(qb) << ", fell " << 1.0 - qb[2] << " (discrete " << fell << ")");
    CHECK(worst < 1e-9);
    CHECK(std::abs(w.gap(qb)) < 1e-12);
    CHECK(1.0 - qb[2] == doctest::Approx(fell).epsilon(1e-9));
  }
}

TEST_CASE("plane_contact, Bullet: compliant plane: resting depth m g / k_e, sinking to first order in dt") {
  for (double k : {1e3, 1e4, 1e5, 1e6}) {
    double err_prev = 0;
    for (double dt : {1e-3, 5e-4}) {
      const Sink s = sink(k, 1.0, dt, 1.0);
      MESSAGE("k_e " << k << ", ζ 1, dt " << dt << " (ω dt " << s.w * dt << "): resting depth / (m g / k_e) − 1 = " << s.rest - 1
                     << ", worst |depth − closed form| " << s.err << " × m g / k_e");
      CHECK(std::abs(s.rest - 1) < 1e-9);
      CHECK(s.err < 0.2 * s.w * dt);
      if (err_prev > 0 && s.w * dt < 0.3) CHECK(err_prev / s.err == doctest::Approx(2.0).epsilon(0.1));
      err_prev = s.err;
    }
  }
  // Undamped: the bounce decays by Bullet's implicit step alone, ~exp(−π ω dt) per period.
  for (double k : {1e3, 1e4}) {
    const Sink s = sink(k, 0.0, 1e-3, 3.0);
    const double predicted = std::exp(-2 * kPi * s.w * 1e-3);
    MESSAGE("k_e " << k << ", ζ 0: third-period / first-period amplitude " << s.decay << " (exp(−2π ω dt) " << predicted << ")");
    CHECK(s.decay == doctest::Approx(predicted).epsilon(0.03));
  }
}

TEST_CASE("plane_contact, Bullet: friction holds below μ f_n and slides above it") {
  const double dt = 1e-3, T = 0.3;
  for (double radius : {0.0, 0.01})
    for (double ratio : {0.8, 1.2}) {
      t::Ball b;
      b.params.mu = 0.5;
      b.params.radius = radius;
      VecN q = VecN::Zero(3), v = VecN::Zero(3), qb, vb;
      q[2] = radius;
      BulletMechanism<Spatial> bullet(b.model(), dt, q, v);
      const double limit = b.params.mu * b.m * b.g, F = ratio * limit;
      const VecN tau = (VecN(3) << F, 0, 0).finished();
      double worst_fx = 0, worst_cone = -1e9;
      for (long i = 1; i <= std::lround(T / dt); ++i) {
        bullet.step(tau);
        bullet.state(qb, vb);
        const Spatial::Vec f = bullet.constraintForce(0);
        worst_fx = std::max(worst_fx, std::abs(f[3] + std::min(F, limit)));
        worst_cone = std::max(worst_cone, f.segment<2>(3).norm() - b.params.mu * f[5]);
      }
      const double a = std::max(0.0, F - limit) / b.m;
      MESSAGE("ρ " << radius << ", F = " << ratio << " μ m g: v_x " << vb[0] << " (a T " << a * T << "), worst |f_x + min(F, μ m g)| "
                   << worst_fx << ", worst |f_t| − μ f_n " << worst_cone << ", moment about P "
                   << bullet.constraintForce(0).head<3>().transpose());
      CHECK(worst_fx < 1e-9);
      CHECK(worst_cone < 1e-9);
      CHECK(vb[0] == doctest::Approx(a * T).epsilon(1e-9));
      // The friction force acts on the Bullet sphere's lowest point: 1 mm − ρ below P for a stand-in.
      CHECK(bullet.constraintForce(0)[1] == doctest::Approx(std::max(0.0, 1e-3 - radius) * std::min(F, limit)).epsilon(1e-6));
    }
}

TEST_CASE("plane_contact, Bullet: arm resting its tip on the table") {
  t::Arm arm;
  const VecN q0 = (VecN(3) << 0.4, 0.5, 0.9).finished();
  arm.params.radius = 0.005;
  arm.params.height = arm.tipPosition(q0).z() - arm.params.radius;  // the tip touches
  const Eigen::Matrix3d J = arm.tipJacobian(q0);
  const VecN G = arm.gravityTorque(q0);
  const double dt = 1e-3, T = 0.5;
  // Frictionless: τ = G − Jᵀ n η_d holds the arm still pressing with η_d (also with products of inertia
  // on link 3: its Bullet link is then turned onto principal axes, and the ball with it).
  for (double product : {0.0, 2e-3}) {
    arm.product = product;
    const double eta_d = 5.0;
    const VecN tau = G - J.transpose() * Pos::UnitZ() * eta_d;
    BulletMechanism<Spatial> bullet(arm.model(), dt, q0, VecN::Zero(3));
    VecN qb, vb;
    double worst_eta = 0, worst_q = 0;
    for (long i = 1; i <= std::lround(T / dt); ++i) {
      bullet.step(tau);
      bullet.state(qb, vb);
      worst_eta = std::max(worst_eta, std::abs(bullet.constraintForce(0)[5] - eta_d));
      worst_q = std::max(worst_q, (qb - q0).cwiseAbs().maxCoeff());
    }
    MESSAGE("frictionless, products " << product << ", τ = G − Jᵀ n η_d: worst |η − η_d| " << worst_eta << ", worst |θ − θ0| " << worst_q << ", gap " << arm.gap(qb)
                                                           << ", f " << bullet.constraintForce(0).transpose());
    CHECK(worst_eta < 1e-8);
    CHECK(worst_q < 1e-9);
  }
  // With friction (μ = 1) and τ = G/2 the tip is pinned: the arm is a structure, f = J⁻ᵀ (G − τ).
  {
    arm.product = 0;
    arm.params.mu = 1.0;
    const VecN tau = 0.5 * G;
    const Pos f = J.transpose().lu().solve(G - tau);
    BulletMechanism<Spatial> bullet(arm.model(), dt, q0, VecN::Zero(3));
    VecN qb, vb;
    double worst_f = 0, worst_q = 0;
    for (long i = 1; i <= std::lround(T / dt); ++i) {
      bullet.step(tau);
      bullet.state(qb, vb);
      worst_f = std::max(worst_f, (bullet.constraintForce(0).tail<3>() - f).norm());
      worst_q = std::max(worst_q, (qb - q0).cwiseAbs().maxCoeff());
    }
    MESSAGE("μ = 1, τ = G/2: J⁻ᵀ(G − τ) = " << f.transpose() << " (cone margin " << f.z() - f.head<2>().norm() << "), Bullet "
                                            << bullet.constraintForce(0).tail<3>().transpose() << ", worst |Δf| " << worst_f
                                            << ", worst |θ − θ0| " << worst_q);
    REQUIRE(f.z() - f.head<2>().norm() > 0);  // inside the cone: the tip sticks
    CHECK(worst_f < 1e-8);
    CHECK(worst_q < 1e-9);
  }
}

TEST_CASE("plane_contact, Bullet: the tip lifts off when the torques pull it up") {
  t::Arm arm;
  const VecN q0 = (VecN(3) << 0.4, 0.5, 0.9).finished();
  arm.params.height = arm.tipPosition(q0).z();
  const Eigen::Matrix3d J = arm.tipJacobian(q0);
  const VecN G = arm.gravityTorque(q0);
  const double dt = 1e-3;
  BulletMechanism<Spatial> bullet(arm.model(), dt, q0, VecN::Zero(3));
  VecN qb, vb;
  const VecN press = G - J.transpose() * Pos::UnitZ() * 5.0, pull = G + J.transpose() * Pos::UnitZ() * 3.0;
  for (int i = 0; i < 100; ++i) bullet.step(press);
  const double eta_pressing = bullet.constraintForce(0)[5];
  bullet.state(qb, vb);
  // Free from the first pulling step: the gap grows as ½ a_n t² with a_n = n·J θ''_free at rest.
  const double a_n = (J * arm.freeAcceleration(qb, vb, pull)).z();
  double worst_eta = 0;
  const int steps = 50;
  for (int i = 1; i <= steps; ++i) {
    bullet.step(pull);
    worst_eta = std::max(worst_eta, std::abs(bullet.constraintForce(0)[5]));
  }
  bullet.state(qb, vb);
  const double T = steps * dt;
  const double gap = 0.5 * a_n * T * (T + dt);  // the first-order step's ½ a T (T + dt)
  MESSAGE("pressing η " << eta_pressing << "; pulling: worst |η| " << worst_eta << ", gap " << arm.gap(qb) << " vs ½ a_n T (T + dt) "
                        << gap << " (a_n " << a_n << ")");
  CHECK(eta_pressing == doctest::Approx(5.0).epsilon(1e-9));
  REQUIRE(a_n > 0);
  CHECK(worst_eta == 0.0);
  CHECK(arm.gap(qb) == doctest::Approx(gap).epsilon(0.01));
}

TEST_CASE("plane_contact, Bullet: two balls on one link share the weight by the lever rule") {
  // A bar on a z carrier (massless) pitching about y, centre of mass a from its middle, balls at both ends.
  const double m = 1.2, L = 0.4, a = 0.05, g = 9.81;
  MechanismModel<Spatial> d;
  d.tree.gravity << 0, 0, 0, 0, 0, -g;
  int b = d.tree.addBody(-1, JointType::Prismatic, Pos::UnitZ(), Spatial::Transform(), Spatial::Mat::Zero());
  b = d.tree.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::Transform(),
                     Spatial::inertia(m, Pos(a, 0, 0), Eigen::Vector3d(1e-4, m * L * L / 12, m * L * L / 12).asDiagonal()));
  PlaneContactParams p;
  p.radius = 0.01;
  for (double end : {-L / 2, L / 2})
    d.constraints.push_back(std::make_shared<PlaneContact<Spatial>>(BodyRef::link(b), Pos(end, 0, 0), Pos::UnitZ(), p));
  const VecN q0 = (VecN(2) << p.radius, 0.0).finished();  // both balls touch z = 0
  BulletMechanism<Spatial> bullet(d, 1e-3, q0, VecN::Zero(2));
  VecN q, v;
  for (int i = 0; i < 300; ++i) bullet.step(VecN::Zero(2));
  bullet.state(q, v);
  const double f1 = bullet.constraintForce(0)[5], f2 = bullet.constraintForce(1)[5];
  MESSAGE(bullet.describe() << "\nleft − m g (L/2 − a)/L: " << f1 - m * g * (L / 2 - a) / L << ", right − m g (L/2 + a)/L: "
                            << f2 - m * g * (L / 2 + a) / L << ", |q − q0| " << (q - q0).norm());
  // The massless carrier's stand-in mass (1e-9 m, spatial_mechanism.cpp) adds its weight, 6e-9 N a ball.
  CHECK(f1 == doctest::Approx(m * g * (L / 2 - a) / L).epsilon(1e-8));
  CHECK(f2 == doctest::Approx(m * g * (L / 2 + a) / L).epsilon(1e-8));
  CHECK((q - q0).norm() < 1e-12);
}

TEST_CASE("plane_contact, Bullet planar: a disk dropped on a floor, on a tilted wall, on a compliant floor") {
  const double dt = 1e-3, H = 0.05, T = 0.5;
  for (bool payload : {false, true}) {
    t::Disk k;
    k.payload = payload;
    k.params.height = -0.1;
    BulletMechanism<Planar> bullet(k.model(), dt, k.state({0.3, k.params.height + H}), VecN::Zero(3));
    VecN q, v;
    double touchdown = -1, after = 0, momentum = 0;
    for (long i = 1; i <= std::lround(T / dt); ++i) {
      bullet.step(VecN::Zero(3));
      bullet.state(q, v);
      const double eta = bullet.constraintForce(0).tail<2>().dot(k.normal);
      if (touchdown >= 0) after = std::max({after, std::abs(k.gap(q)), v.norm()});
      else if (eta > 0) touchdown = double(i) * dt;
      momentum += eta * dt;
    }
    const double t_fall = std::sqrt(2 * H / k.g);
    MESSAGE(std::string(payload ? "payload" : "tree") << " disk: " << bullet.describe() << "\ntouchdown " << touchdown << " (free fall "
                                           << t_fall << "), worst |gap|, |v| after " << after << ", η " << bullet.constraintForce(0)[2]
                                           << ", Σ η dt " << momentum << " (m g T " << k.m * k.g * T << ")");
    CHECK(touchdown >= t_fall - 1e-12);
    CHECK(touchdown <= t_fall + 2 * dt);
    CHECK(after < 1e-12);
    CHECK(bullet.constraintForce(0)[2] == doctest::Approx(k.m * k.g).epsilon(1e-9));
    CHECK(momentum == doctest::Approx(k.m * k.g * T).epsilon(1e-9));
  }
  {  // a frictionless wall tilted by α: the disk slides down it as the discrete step predicts
    const double alpha = 0.5, T2 = 0.3;
    t::Disk k;
    k.normal = {std::sin(alpha), std::cos(alpha)};
    k.params.radius = 0.02;
    const t::Disk::Pos c0 = (k.params.height + k.params.radius) * k.normal;
    BulletMechanism<Planar> bullet(k.model(), dt, k.state(c0), VecN::Zero(3));
    VecN q, v;
    double worst = 0;
    for (long i = 1; i <= std::lround(T2 / dt); ++i) {
      bullet.step(VecN::Zero(3));
      bullet.state(q, v);
      worst = std::max(worst, std::abs(bullet.constraintForce(0).tail<2>().dot(k.normal) - k.m * k.g * std::cos(alpha)));
    }
    const double s = (k.centre(q) - c0).dot(t::Disk::Pos(std::cos(alpha), -std::sin(alpha)));
    const double s_step = 0.5 * k.g * std::sin(alpha) * T2 * (T2 + dt);
    MESSAGE("tilted wall: slid " << s << " (discrete " << s_step << "), worst |η − m g cos α| " << worst << ", gap " << k.gap(q));
    CHECK(s == doctest::Approx(s_step).epsilon(1e-9));
    CHECK(worst < 1e-8);
    CHECK(std::abs(k.gap(q)) < 1e-12);
  }
  {  // compliant floor, critically damped: resting depth m g / k_e
    t::Disk k;
    k.params.stiffness = 2e4;
    k.params.damping = 2 * std::sqrt(k.params.stiffness * k.m);
    BulletMechanism<Planar> bullet(k.model(), dt, k.state({0, 0}), VecN::Zero(3));
    VecN q, v;
    for (int i = 0; i < 1000; ++i) bullet.step(VecN::Zero(3));
    bullet.state(q, v);
    const double exact = k.m * k.g / k.params.stiffness;
    MESSAGE("compliant floor: depth " << -k.gap(q) << " (m g / k_e " << exact << ")");
    CHECK(-k.gap(q) == doctest::Approx(exact).epsilon(1e-9));
  }
}

TEST_CASE("plane_contact, Bullet planar: friction rolls a pushed disk, or lets it skid") {
  // Pushed at its centre by F, a disk of radius ρ rolls while F I/(I + m ρ²) ≤ μ m g: a = F/(m + I/ρ²),
  // ω = −v/ρ; above, it skids: a = (F − μ m g)/m, and the friction μ m g spins it at μ m g ρ / I.
  const double dt = 1e-3, T = 0.2;
  t::Disk k;
  k.params.radius = 0.02;
  k.params.mu = 0.3;
  k.I = 0.5 * k.m * k.params.radius * k.params.radius;
  const double rho = k.params.radius, limit = k.params.mu * k.m * k.g, share = k.I / (k.I + k.m * rho * rho);
  for (double ratio : {0.8, 1.5}) {
    const double F = ratio * limit / share;
    BulletMechanism<Planar> bullet(k.model(), dt, k.state({0, rho}), VecN::Zero(3));
    VecN q, v;
    for (long i = 1; i <= std::lround(T / dt); ++i) bullet.step((VecN(3) << F, 0, 0).finished());
    bullet.state(q, v);
    const bool rolls = ratio < 1;
    const double a = rolls ? F / (k.m + k.I / (rho * rho)) : (F - limit) / k.m;
    const double w = rolls ? -a * T / rho : -limit * rho / k.I * T;
    const double f = rolls ? -F * share : -limit;
    MESSAGE(std::string(rolls ? "rolls" : "skids") << ": v " << v[0] << " (" << a * T << "), ω " << v[2] << " (" << w << "), f_x "
                                        << bullet.constraintForce(0)[1] << " (" << f << ")");
    CHECK(v[0] == doctest::Approx(a * T).epsilon(1e-6));
    CHECK(v[2] == doctest::Approx(w).epsilon(1e-6));
    CHECK(bullet.constraintForce(0)[1] == doctest::Approx(f).epsilon(1e-6));
  }
}

TEST_CASE("plane_contact, Bullet: descriptions it cannot model are refused naming what") {
  t::Ball b;
  auto m = b.model();
  PlaneContactParams other;
  other.height = 0.5;
  m.constraints.push_back(std::make_shared<PlaneContact<Spatial>>(BodyRef::link(2), Pos::Zero(), Pos::UnitZ(), other));
  std::string what;
  try {
    BulletMechanism<Spatial>(m, 1e-3, VecN::Zero(3), VecN::Zero(3));
  } catch (const std::invalid_argument& e) {
    what = e.what();
  }
  CHECK(what.find("carries balls against different planes") != std::string::npos);
  b.params.mu = 12;
  what.clear();
  try {
    BulletMechanism<Spatial>(b.model(), 1e-3, VecN::Zero(3), VecN::Zero(3));
  } catch (const std::invalid_argument& e) {
    what = e.what();
  }
  CHECK(what.find("> 10: Bullet clips") != std::string::npos);
}

TEST_CASE("plane_contact, Bullet planar: a contact inside a weld-made fixed joint's subtree (slider crank)") {
  // Cut at joint 1, Bullet's tree is world → slider → (weld) link 3 → link 2 → link 1, and the weld's
  // force is the Newton–Euler balance of links 1–3: a table under link 2 must enter it. The slider's own
  // Newton equation (free x: m_s a_x = the weld's force on it) checks that balance independently.
  t::SliderCrankModel p;
  const double l[3] = {0.5, 0.4, 0.3}, mass[3] = {1.0, 0.8, 0.5};
  for (int i = 0; i < 3; ++i) p.links[std::size_t(i)] = {l[i], mass[i], mass[i] * l[i] * l[i] / 12.0, Eigen::Vector2d(l[i] / 2, 0)};
  p.load_mass = 0.5;
  p.gravity = {0.0, -9.81};
  const double t1 = kPi / 4, a12 = std::asin(-l[0] * std::sin(t1) / l[1]);
  p.q0 = {t1, a12 - t1, -a12};
  p.qd0.setZero();
  VecN q0(4), v0 = VecN::Zero(4);
  q0 << p.q0, t::sliderOf(p, p.q0, p.qd0)[0];
  const double dt = 1e-3;
  // Link 2's middle moves along u from rest: put a frictionless table across it, facing −u.
  MechanismModel<Planar> d = t::sliderCrankDescription(p);
  Planar::Pos u;
  {
    BulletMechanism<Planar> free(d, dt, q0, v0);
    free.step(VecN::Zero(3));
    VecN q, v;
    free.state(q, v);
    const double a1 = q0[0], a12_ = q0[0] + q0[1];
    const Planar::Pos e1(-std::sin(a1), std::cos(a1)), e12(-std::sin(a12_), std::cos(a12_));
    u = (l[0] * v[0] * e1 + l[1] / 2 * (v[0] + v[1]) * e12).normalized();  // velocity of link 2's middle
  }
  const Planar::Pos mid = l[0] * Planar::Pos(std::cos(q0[0]), std::sin(q0[0])) +
                          l[1] / 2 * Planar::Pos(std::cos(q0[0] + q0[1]), std::sin(q0[0] + q0[1]));
  PlaneContactParams table;
  table.height = (-u).dot(mid);
  d.constraints.push_back(std::make_shared<PlaneContact<Planar>>(BodyRef::link(1), Planar::Pos(l[1] / 2, 0), -u, table));
  BulletMechanism<Planar> bullet(d, dt, q0, v0);
  VecN q, v, v_prev = v0;
  double worst = 0, eta_min = 1e9;
  for (int i = 0; i < 100; ++i) {
    bullet.step(VecN::Zero(3));
    bullet.state(q, v);
    worst = std::max(worst, std::abs(bullet.constraintForce(0)[1] - p.load_mass * (v[3] - v_prev[3]) / dt));
    eta_min = std::min(eta_min, bullet.constraintForce(1).tail<2>().dot(-u));
    v_prev = v;
  }
  MESSAGE(bullet.describe() << "\nthe table presses with η ≥ " << eta_min << " N; worst |f_weld,x − m_s a_x| " << worst << " N");
  CHECK(eta_min > 0.1);
  CHECK(worst < 1e-8);
}

TEST_CASE("plane_contact, Bullet: runs are deterministic (same input, same bytes)") {
  auto run = [] {
    t::Arm arm;
    arm.params.mu = 0.4;
    arm.params.stiffness = 2e4;
    arm.params.damping = 50;
    const VecN q0 = (VecN(3) << 0.4, 0.5, 0.9).finished();
    arm.params.height = arm.tipPosition(q0).z() + 0.002;  // the tip starts 2 mm deep
    BulletMechanism<Spatial> bullet(arm.model(), 1e-3, q0, VecN::Zero(3));
    VecN q, v;
    std::vector<double> out;  // (VecN has a fixed capacity)
    for (int i = 0; i < 200; ++i) {
      bullet.step(arm.gravityTorque(q0) * 0.8);
      bullet.state(q, v);
      const Spatial::Vec f = bullet.constraintForce(0);
      out.insert(out.end(), q.data(), q.data() + q.size());
      out.insert(out.end(), v.data(), v.data() + v.size());
      out.insert(out.end(), f.data(), f.data() + 6);
    }
    return out;
  };
  const std::vector<double> a = run(), b = run();
  REQUIRE(a.size() == b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}
