// The unilateral plane contact (physics/constraints/plane_contact.h) through the generic mechanism's
// open/close handling (ConstrainedMechanism::updateContacts), against closed forms:
//  * a ball dropped from H touches down at √(2H/g) (within a step), the plastic impact removes the
//    normal velocity and keeps the tangential one (frictionless plane), then it rests with η = m g;
//  * located inside its step (stepLocatingContacts), the touchdown lands on the plane: no step ends past it;
//  * pulled up harder than its weight, the contact opens and the ball rises as ½ (F/m − g) t²;
//  * a two-link arm resting its tip on the table presses with the η of its static balance, τ = G − Jᵀ f;
//  * a compliant plane (k_e) holds the ball at depth m g / k_e, and without damping conserves energy.
#include <doctest/doctest.h>

#include <cmath>

#include "physics/constrained_mechanism.h"
#include "physics/constraints/plane_contact.h"

using namespace dyn;

namespace {

using Pos = Planar::Pos;
constexpr double kM = 0.5, kG = 9.81, kRho = 0.01, kI = 1e-4;

// A ball on x and y carriers (planar, gravity −y) above the table y = 0: q = (x, y).
MechanismModel<Planar> ball(const PlaneContactParams& p) {
  MechanismModel<Planar> d;
  d.tree.gravity << 0, 0, -kG;
  const int bx = d.tree.addBody(-1, JointType::Prismatic, Pos(1, 0), Planar::Transform{}, Planar::Mat::Zero());
  const int by = d.tree.addBody(bx, JointType::Prismatic, Pos(0, 1), Planar::Transform{}, Planar::inertia(kM, Pos::Zero(), kI));
  d.constraints.push_back(std::make_shared<PlaneContact<Planar>>(BodyRef::link(by), Pos::Zero(), Pos(0, 1), p));
  return d;
}

PlaneContactParams rigid() {
  PlaneContactParams p;
  p.radius = kRho;
  return p;
}

struct Run {
  ConstrainedMechanism<Planar> mech;
  StepOptions options;
  VecN q, v;
  explicit Run(MechanismModel<Planar> d, Integrator integrator = Integrator::RK4) : mech(std::move(d)) {
    options.dt = 1e-3;
    options.integrator = integrator;
    options.drift.kind = Drift::Projection;
  }
  // One step as the harness takes it: contacts first, then the integrator. Returns η at the step's start.
  double step(const VecN& tau) {
    mech.updateContacts(q, v, tau);
    const double eta = mech.solve(q, v, tau).eta[0];
    REQUIRE(dyn::step(mech, options, tau, q, v));
    return eta;
  }
};

}  // namespace

TEST_CASE("plane contact: a dropped ball touches down, stops its normal motion, and rests on its weight") {
  const double H = 0.05, vx = 0.3;
  Run run(ball(rigid()));
  run.q = VecN(2);
  run.v = VecN(2);
  run.q << 0.0, kRho + H;
  run.v << vx, 0.0;
  const VecN tau = VecN::Zero(2);
  double touchdown = -1, eta = 0;
  for (int k = 0; k < 400; ++k) {
    const bool was_closed = run.mech.closed(0);
    eta = run.step(tau);
    if (!was_closed && run.mech.closed(0) && touchdown < 0) touchdown = k * run.options.dt;
    CHECK(eta >= 0.0);  // a closed contact never pulls
  }
  // Detected at the first step start at or below the plane: within one step after √(2H/g).
  const double t_fall = std::sqrt(2 * H / kG);
  CHECK(touchdown >= t_fall - 1e-12);
  CHECK(touchdown <= t_fall + 1.5 * run.options.dt);
  CHECK(run.mech.closed(0));
  // Plastic and frictionless: no normal speed, the tangential speed kept, the gap closed.
  CHECK(std::abs(run.v[1]) < 1e-12);
  CHECK(std::abs(run.v[0] - vx) < 1e-12);
  CHECK(std::abs(run.q[1] - kRho) < 1e-9);
  CHECK(std::abs(eta - kM * kG) < 1e-9);
}

TEST_CASE("plane contact: the touchdown located inside its step lands on the plane at √(2H/g)") {
  // stepLocatingContacts: the step that crosses the plane is retaken to the crossing, the contact closed
  // there (its impact), and finished resting. No step ends past the plane; the ball's height at every
  // step end is the closed form, free fall until √(2H/g) and ρ after; the impact stops v_y at once.
  const double H = 0.05, vx = 0.3;
  for (const Integrator integrator : {Integrator::RK4, Integrator::SemiImplicitEuler}) {
    const std::string scheme = name(integrator);
    CAPTURE(scheme);
    Run run(ball(rigid()), integrator);
    run.q = VecN(2);
    run.v = VecN(2);
    run.q << 0.0, kRho + H;
    run.v << vx, 0.0;
    const VecN tau = VecN::Zero(2);
    const double dt = run.options.dt, t_fall = std::sqrt(2 * H / kG);
    double depth = 0, worst = 0;
    for (int k = 1; k <= 200; ++k) {
      run.mech.updateContacts(run.q, run.v, tau);
      REQUIRE(run.mech.stepLocatingContacts(run.options, tau, run.q, run.v));
      const double t = k * dt;
      depth = std::max(depth, kRho - run.q[1]);
      if (integrator == Integrator::RK4) {
        const double y = t < t_fall ? kRho + H - 0.5 * kG * t * t : kRho;
        worst = std::max(worst, std::abs(run.q[1] - y));
      }
      if (t > t_fall + dt) {
        CHECK(run.mech.closed(0));
        CHECK(std::abs(run.v[1]) < 1e-12);
      }
    }
    MESSAGE(scheme, ": deepest ", depth, " m; RK4's height against the closed form ", worst, " m");
    CHECK(depth < 1e-12);
    CHECK(worst < 1e-11);
    CHECK(std::abs(run.v[0] - vx) < 1e-12);
  }
}

TEST_CASE("plane contact: pulled up harder than its weight the ball lifts off") {
  Run run(ball(rigid()));
  run.q = VecN(2);
  run.v = VecN::Zero(2);
  run.q << 0.0, kRho;
  run.mech.setClosed(0, true);
  VecN tau = VecN::Zero(2);
  for (int k = 0; k < 50; ++k) run.step(tau);
  CHECK(run.mech.closed(0));
  CHECK(std::abs(run.q[1] - kRho) < 1e-12);
  // A lift of 1.5 m g: the solve would need η < 0, so the contact opens at once.
  const double F = 1.5 * kM * kG, T = 0.2;
  tau[1] = F;
  const double y0 = run.q[1];
  const int steps = int(std::lround(T / run.options.dt));
  for (int k = 0; k < steps; ++k) {
    CHECK(run.step(tau) == 0.0);
    CHECK(!run.mech.closed(0));
  }
  const double a = F / kM - kG;
  CHECK(std::abs(run.q[1] - y0 - 0.5 * a * T * T) < 1e-9);
}

TEST_CASE("plane contact: a two-link arm resting its tip on the table presses with its static balance") {
  // Links of length 0.4 and 0.3 from the origin, table y = −0.35 under the tip.
  const double l1 = 0.4, l2 = 0.3, m1 = 1.2, m2 = 0.8;
  MechanismModel<Planar> d;
  d.tree.gravity << 0, 0, -kG;
  const int b1 = d.tree.addBody(-1, JointType::Revolute, Pos(0, 0), Planar::Transform{}, Planar::inertia(m1, Pos(l1 / 2, 0), m1 * l1 * l1 / 12));
  const int b2 = d.tree.addBody(b1, JointType::Revolute, Pos(0, 0), Planar::Transform{Planar::Rot::Identity(), Pos(l1, 0)},
                                Planar::inertia(m2, Pos(l2 / 2, 0), m2 * l2 * l2 / 12));
  PlaneContactParams p;
  p.height = -0.35;
  d.constraints.push_back(std::make_shared<PlaneContact<Planar>>(BodyRef::link(b2), Pos(l2, 0), Pos(0, 1), p));
  Run run(std::move(d));
  // A configuration with the tip on the table: θ1 = −0.5, θ2 from y_tip = −0.35.
  const double th1 = -0.5, th2 = std::asin((-0.35 - l1 * std::sin(th1)) / l2) - th1;
  run.q = VecN(2);
  run.v = VecN::Zero(2);
  run.q << th1, th2;
  // Joint torques that hold the arm with a chosen downward tip force η_d: τ = G − Jᵀ (0, η_d).
  const double eta_d = 3.0;
  const VecN G = run.mech.gravityTorque(run.q);
  MatN J;
  VecN Jd;
  run.mech.pointJacobian(b2, Pos(l2, 0), run.q, run.v, J, Jd);
  const VecN tau = G - J.row(2).transpose() * eta_d;
  double eta = 0;
  for (int k = 0; k < 100; ++k) eta = run.step(tau);
  CHECK(run.mech.closed(0));
  CHECK(std::abs(eta - eta_d) < 1e-9);
  CHECK(run.v.norm() < 1e-9);
  // Less than gravity needs, and the arm lifts its tip: the contact opens.
  for (int k = 0; k < 100; ++k) run.step(G - J.row(2).transpose() * (-1.0));
  CHECK(!run.mech.closed(0));
}

TEST_CASE("plane contact: a compliant table holds the ball at m g / k_e and, undamped, conserves energy") {
  PlaneContactParams p = rigid();
  p.stiffness = 2e4;
  SUBCASE("damped: rests at the static depth") {
    p.damping = 2 * std::sqrt(p.stiffness * kM);  // critical
    Run run(ball(p));
    run.q = VecN(2);
    run.v = VecN::Zero(2);
    run.q << 0.0, kRho;
    double eta = 0;
    for (int k = 0; k < 500; ++k) eta = run.step(VecN::Zero(2));
    CHECK(std::abs(run.q[1] - (kRho - kM * kG / p.stiffness)) < 1e-9);
    CHECK(std::abs(eta - kM * kG) < 1e-6);
  }
  SUBCASE("undamped: bounces elastically") {
    Run run(ball(p));
    run.options.dt = 2e-4;
    run.q = VecN(2);
    run.v = VecN::Zero(2);
    run.q << 0.0, kRho + 0.02;
    double max_h = 0;
    for (int k = 0; k < 1500; ++k) {
      run.step(VecN::Zero(2));
      if (k > 500) max_h = std::max(max_h, run.q[1] - kRho);
    }
    // Off the table the energy is the ball's alone (the spring is slack): it comes back up to 2 cm.
    CHECK(std::abs(max_h - 0.02) < 2e-4);
    CHECK(run.q[1] > kRho - 0.01);
  }
}

TEST_CASE("plane contact: its row is the contact point's Jacobian rows combined along the normal") {
  // addDirectionJacobian (one row along d) against addPointJacobian's translation rows, dotted with d:
  // on a link of a planar arm and on a payload.
  MechanismModel<Planar> d;
  d.tree.gravity << 0, 0, -kG;
  int b = d.tree.addBody(-1, JointType::Revolute, Pos::Zero(), Planar::Transform{}, Planar::inertia(1.0, Pos(0.2, 0), 0.01));
  b = d.tree.addBody(b, JointType::Revolute, Pos::Zero(), Planar::translation({0.4, 0}), Planar::inertia(0.5, Pos(0.15, 0), 0.005));
  Payload load;
  load.mass = 0.3, load.inertia = 1e-3;
  load.pose0 = {0.4, 0.5, 0.2};
  d.payloads.push_back(load);
  d.constraints.push_back(std::make_shared<PlaneContact<Planar>>(BodyRef::link(b), Pos(0.3, 0), Pos(0, 1), rigid()));
  ConstrainedMechanism<Planar> mech(d);
  VecN q(5);
  q << 0.4, -0.9, 0.4, 0.5, 0.2;
  mech.stage(q);
  const auto& k = mech.kinematics();
  const Pos dir = Pos(0.6, -0.8);
  const Pos p(0.35, 0.25);
  for (const BodyRef body : {BodyRef::link(1), BodyRef::payload(0)}) {
    MatN J = MatN::Zero(1, 2), A = MatN::Zero(1, 3), Jr = MatN::Zero(2, 2), Ar = MatN::Zero(2, 3);
    k.addDirectionJacobian(body, p, dir, -1.0, 0, J, A);
    k.addPointJacobian(body, p, {false, true, true}, -1.0, 0, Jr, Ar);
    const MatN Jd = dir.transpose() * Jr, Ad = dir.transpose() * Ar;
    CHECK((J - Jd).norm() < 1e-15);
    CHECK((A - Ad).norm() < 1e-15);
    CHECK(J.norm() + A.norm() > 0.1);  // not trivially zero
  }
}

TEST_CASE("plane contact: a spatial link's row and bias, read in place, are MechanismKinematics' bit for bit") {
  // PlaneContact<Spatial> reads the link's X_world, S_w, v_w and a_w itself (no calls): the same sums as
  // k.position + k.addDirectionJacobian (row) and k.directionBias (bias), on a turning 3-joint arm with a
  // tilted normal, so every column and term counts.
  using SPos = Spatial::Pos;
  MechanismModel<Spatial> d;
  d.tree.gravity << 0, 0, 0, 0, 0, -kG;
  const Spatial::Mat I = Spatial::inertia(1.0, SPos(0.1, 0, 0), Eigen::Matrix3d::Identity() * 0.01);
  int b = d.tree.addBody(-1, JointType::Revolute, SPos::UnitZ(), Spatial::Transform(), I);
  b = d.tree.addBody(b, JointType::Revolute, SPos::UnitY(), Spatial::translation(SPos(0, 0, 0.3)), I);
  b = d.tree.addBody(b, JointType::Revolute, SPos(0.3, 0.8, 0.2).normalized(), Spatial::translation(SPos(0.3, 0, 0)), I);
  const SPos centre(0.35, 0.02, -0.01), normal = SPos(0.1, -0.2, 1.0).normalized();
  const auto contact = std::make_shared<PlaneContact<Spatial>>(BodyRef::link(b), centre, normal, rigid());
  d.constraints.push_back(contact);
  ConstrainedMechanism<Spatial> mech(d);
  VecN q(3), v(3);
  q << 0.7, -0.4, 1.1;
  v << 1.3, -0.8, 2.1;
  mech.stage(q, &v);
  const auto& k = mech.kinematics();
  VecN phi = VecN::Zero(1), b_row = VecN::Zero(1), b_ref = VecN::Zero(1);
  MatN J = MatN::Zero(1, 3), A = MatN::Zero(1, 0), J_ref = MatN::Zero(1, 3), A_ref = MatN::Zero(1, 0);
  contact->position(k, 0, phi, J, A);
  contact->bias(k, 0, b_row);
  // (The contact's own unit normal: normalising `normal` again may move its last bits.)
  const SPos c = k.position(BodyRef::link(b), centre), n = contact->normal();
  k.addDirectionJacobian(BodyRef::link(b), c, n, -1.0, 0, J_ref, A_ref);
  b_ref[0] = -k.directionBias(BodyRef::link(b), c, n);
  CHECK(phi[0] == -(n.dot(c) - kRho - 0.0));
  for (int j = 0; j < 3; ++j) CHECK(J(0, j) == J_ref(0, j));
  CHECK(b_row[0] == b_ref[0]);
  CHECK(J.norm() > 0.1);
  CHECK(std::abs(b_row[0]) > 0.1);
}
