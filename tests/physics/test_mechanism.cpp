// The generic constrained mechanism (physics/constrained_mechanism.h) built from descriptions, against
// independent references, and each constraint kind against the checks RBDL asks of a new constraint:
//  * the slider crank described as data equals eq. (2) assembled by hand from the tree algorithms;
//  * a point closure pinning two one-link trees equals the two-link chain (the joint-coordinate model);
//  * a point contact (rotation free) equals a chain with one more revolute joint;
//  * constraint forces do no work along the free motion; a static hold is held with the forces asked for;
//  * passive runs conserve energy and stay on φ = 0; fixed sizes equal bounded sizes.
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <random>

#include "physics/constrained_mechanism_impl.h"
#include "physics/constraints/point_closure.h"
#include "physics/constraints/point_contact.h"
#include "tests/physics/arms.h"

using namespace dyn;

namespace {

using Pos = Planar::Pos;
const Eigen::Vector3d kGravity(0, 0, -9.81);

// A planar link of length l hanging from `parent` at `offset` (its joint), centre of mass mid-link.
int addLink(TreeModel<Planar>& t, int parent, const Pos& offset, double l, double m, double com_y = 0.0) {
  return t.addBody(parent, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset),
                   Planar::inertia(m, Pos(l / 2, com_y), m * l * l / 12));
}

// The slider crank: the 3-link test arm whose tip is welded to a slider free along world x.
MechanismModel<Planar> sliderCrank(double load_mass = 0.5) {
  MechanismModel<Planar> d;
  d.tree = test::planarArm();
  Payload slider;
  slider.mass = load_mass;
  slider.inertia = load_mass * 0.05 * 0.05 / 6;
  slider.free = {false, true, false};
  d.payloads.push_back(slider);
  d.constraints.push_back(std::make_shared<PointClosure<Planar>>(BodyRef::link(2), Pos(0.2, 0.0), BodyRef::payload(0),
                                                                 Pos::Zero(), PointClosure<Planar>::all()));
  return d;
}

struct Random {
  std::mt19937_64 rng{11};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  VecN vec(int n, double scale = 1.0) {
    VecN v(n);
    for (int i = 0; i < n; ++i) v[i] = scale * u(rng);
    return v;
  }
};

// One passive RK4 + projection run: the largest |E − E0| relative to the energy that changes form,
// and the largest |φ|.
template <class M>
std::pair<double, double> passiveRun(M& mech, VecN q, VecN v, double T, double dt = 1e-3) {
  StepOptions o;
  o.dt = dt;
  REQUIRE(projectPositions(mech, o.drift, q));
  projectVelocities(mech, q, v);
  const double e0 = mech.energy(q, v);
  const VecN tau = VecN::Zero(mech.n());
  double de = 0, phi = 0, swing = 0;
  for (int k = 0; k < int(T / dt); ++k) {
    REQUIRE(step(mech, o, tau, q, v));
    de = std::max(de, std::abs(mech.energy(q, v) - e0));
    swing = std::max(swing, mech.kineticEnergy(q, v));
    phi = std::max(phi, mech.residual(q));
  }
  REQUIRE(swing > 0.05);  // the mechanism really moved: energy changed form
  return {de / swing, phi};
}

}  // namespace

TEST_CASE("the slider crank as data equals eq. (2) assembled by hand (random states, 1e-12)") {
  ConstrainedMechanism<Planar> generic(sliderCrank());
  ConstrainedMechanism<Planar, 3, 3, 1> fixed(sliderCrank());
  TreeModel<Planar> arm = test::planarArm();
  TreeData<Planar> data(arm);
  Random r;
  for (int trial = 0; trial < 20; ++trial) {
    CAPTURE(trial);
    const VecN q = r.vec(4, 2.0), v = r.vec(4, 3.0), tau = r.vec(3, 5.0);
    // By hand: the tree, the tip Jacobian, A = (0, 1, 0), M_c = m_c (lecture §3, load separate).
    ConstrainedProblem p;
    forwardKinematics(arm, q.head(3), v.head(3), data);
    p.M = crba(arm, data);
    p.h = rnea(arm, data, v.head(3), VecN::Zero(3));
    p.tau = tau;
    pointJacobian(arm, data, 2, Pos(0.2, 0.0), p.J, p.Jdot_qd);
    p.A = Eigen::Vector3d(0, 1, 0);
    p.Mc = MatN::Constant(1, 1, 0.5);
    const ConstrainedSolution ref = solveConstrained(p);
    REQUIRE(ref.ok);
    const auto s = generic.solve(q, v, tau);
    const auto sf = fixed.solve(q, v, tau);
    const double scale = std::max(1.0, ref.f.norm());
    CHECK((s.qdd - ref.qdd).norm() < 1e-12 * std::max(1.0, ref.qdd.norm()));
    CHECK(std::abs(s.alpha_c[0] - ref.alpha_c[0]) < 1e-12 * std::max(1.0, std::abs(ref.alpha_c[0])));
    CHECK((s.f - ref.f).norm() < 1e-12 * scale);
    CHECK((VecN(sf.qdd) - s.qdd).norm() < 1e-12 * std::max(1.0, ref.qdd.norm()));
    CHECK((VecN(sf.f) - s.f).norm() < 1e-12 * scale);
    // φ = (θ1+θ2+θ3, x_T − x_c, y_T) and G = [J, −A].
    VecN phi;
    MatN G;
    generic.constraint(q, phi, G);
    const Pos tip = pointPosition(data, 2, Pos(0.2, 0.0));
    CHECK(std::abs(phi[0] - std::remainder(q.head(3).sum(), 2 * M_PI)) < 1e-12);
    CHECK(std::abs(phi[1] - (tip.x() - q[3])) < 1e-12);
    CHECK(std::abs(phi[2] - tip.y()) < 1e-12);
    CHECK((G.leftCols(3) - p.J).norm() < 1e-12);
    CHECK((G.col(3) - Eigen::Vector3d(0, -1, 0)).norm() == 0.0);
    // The force of constraint 0 is f (the arm on the slider).
    CHECK((generic.constraintForce(0, s) - Eigen::Vector3d(s.f)).norm() == 0.0);
  }
}

TEST_CASE("point closure: a pin between two trees equals the two-link chain") {
  // Chain: link 2 hangs from link 1's tip by a revolute joint. Description: link 1 hangs from the
  // world; link 2 rides on massless x and y carriages (a second tree) with its own revolute joint, and
  // a pin (x, y rows) holds link 2's origin on link 1's tip. Absolute angles: chain θ1, θ1 + θ2; trees
  // θ1 and ψ2.
  const double l1 = 0.5, l2 = 0.4;
  TreeModel<Planar> chain;
  addLink(chain, -1, Pos::Zero(), l1, 1.2, 0.03);
  addLink(chain, 0, Pos(l1, 0), l2, 0.7, -0.02);
  chain.gravity = kGravity;
  MechanismModel<Planar> d;
  addLink(d.tree, -1, Pos::Zero(), l1, 1.2, 0.03);
  const int cx = d.tree.addBody(-1, JointType::Prismatic, Pos(1, 0), Planar::Transform{}, Planar::Mat::Zero());
  const int cy = d.tree.addBody(cx, JointType::Prismatic, Pos(0, 1), Planar::Transform{}, Planar::Mat::Zero());
  const int link2 = addLink(d.tree, cy, Pos::Zero(), l2, 0.7, -0.02);
  d.tree.gravity = kGravity;
  d.constraints.push_back(std::make_shared<PointClosure<Planar>>(BodyRef::link(0), Pos(l1, 0), BodyRef::link(link2),
                                                                 Pos::Zero(), PointClosure<Planar>::translations()));
  ConstrainedMechanism<Planar> mech(d);
  TreeData<Planar> data(chain);
  Random r;
  for (int trial = 0; trial < 10; ++trial) {
    CAPTURE(trial);
    const VecN qc = r.vec(2, 2.0), vc = r.vec(2, 3.0), tc = r.vec(2, 2.0);
    forwardKinematics(chain, qc, vc, data);
    const MatN M = crba(chain, data);
    const VecN h = rnea(chain, data, vc, VecN::Zero(2));
    const VecN qdd = M.lu().solve(tc - h);
    // The same state in the trees: the carriages at link 1's tip and moving with it; the chain's τ2
    // acts between the links: +τ2 on link 2, −τ2 on link 1.
    const Pos tip = pointPosition(data, 0, Pos(l1, 0));
    const Planar::Vec vtip = Planar::motion(Planar::translation(tip), Planar::motionInverse(data.X_world[0], data.v[0]));
    VecN q(4), v(4), tau(4);
    q << qc[0], tip.x(), tip.y(), qc[0] + qc[1];
    v << vc[0], vtip[1], vtip[2], vc[0] + vc[1];
    tau << tc[0] - tc[1], 0, 0, tc[1];
    REQUIRE(mech.residual(q, v) < 1e-12);
    const auto s = mech.solve(q, v, tau);
    REQUIRE(s.ok);
    CHECK(std::abs(s.qdd[0] - qdd[0]) < 1e-9 * std::max(1.0, qdd.norm()));
    CHECK(std::abs(s.qdd[3] - (qdd[0] + qdd[1])) < 1e-9 * std::max(1.0, qdd.norm()));
    // A pin passes no moment.
    CHECK(mech.constraintForce(0, s)[0] == 0.0);
  }
}

TEST_CASE("point contact: a payload held at one point equals a chain with one more revolute joint") {
  // A 2-link finger whose tip holds a free box by a point contact (the box's rotation is free): the same
  // as a 3-link chain whose third link is the box, hinged at the contact point.
  const double l1 = 0.3, l2 = 0.25, m_box = 0.4, I_box = 0.002;
  const Pos contact_on_box(-0.05, 0.01);  // the contact point in the box frame (box frame at its centre)
  MechanismModel<Planar> d;
  addLink(d.tree, -1, Pos::Zero(), l1, 1.0);
  addLink(d.tree, 0, Pos(l1, 0), l2, 0.6);
  d.tree.gravity = kGravity;
  Payload box;
  box.mass = m_box;
  box.inertia = I_box;
  d.payloads.push_back(box);
  d.constraints.push_back(std::make_shared<PointContact<Planar>>(BodyRef::link(1), Pos(l2, 0), BodyRef::payload(0),
                                                                 contact_on_box, Pos(-1, 0), 0.6));
  ConstrainedMechanism<Planar> mech(d);
  TreeModel<Planar> chain;
  addLink(chain, -1, Pos::Zero(), l1, 1.0);
  addLink(chain, 0, Pos(l1, 0), l2, 0.6);
  chain.addBody(1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(Pos(l2, 0)),
                Planar::inertia(m_box, -contact_on_box, I_box));  // link 3's origin at the contact point
  chain.gravity = kGravity;
  TreeData<Planar> data(chain);
  Random r;
  for (int trial = 0; trial < 10; ++trial) {
    CAPTURE(trial);
    const VecN qc = r.vec(3, 2.0), vc = r.vec(3, 3.0);
    VecN tc = r.vec(3, 2.0);
    tc[2] = 0;  // no torque at the contact
    forwardKinematics(chain, qc, vc, data);
    const VecN qdd = crba(chain, data).lu().solve(tc - rnea(chain, data, vc, VecN::Zero(3)));
    // The box's pose and rates from the chain's third link.
    const double psi = qc.sum(), w = vc.sum();
    const Pos c = pointPosition(data, 2, Pos(-contact_on_box));
    const Planar::Vec vbox = Planar::motion(Planar::translation(c), Planar::motionInverse(data.X_world[2], data.v[2]));
    VecN q(5), v(5);
    q << qc[0], qc[1], psi, c.x(), c.y();
    v << vc[0], vc[1], w, vbox[1], vbox[2];
    const auto s = mech.solve(q, v, tc.head(2));
    REQUIRE(s.ok);
    CHECK(mech.residual(q) < 1e-12);
    CHECK(std::abs(s.qdd[0] - qdd[0]) < 1e-9 * std::max(1.0, qdd.norm()));
    CHECK(std::abs(s.qdd[1] - qdd[1]) < 1e-9 * std::max(1.0, qdd.norm()));
    CHECK(std::abs(s.alpha_c[0] - qdd.sum()) < 1e-9 * std::max(1.0, qdd.norm()));
    // No moment passes, and the contact reports its force in contact axes: f_n = −f·n, f_t = f·t.
    const Planar::Vec f = mech.constraintForce(0, s);
    CHECK(f[0] == 0.0);
    double rep[3];
    mech.constraintReport(0, s, rep);
    const Pos n = Planar::rotation(psi).transpose() * Pos(-1, 0);
    CHECK(std::abs(rep[0] + f.tail<2>().dot(n)) < 1e-12);
    CHECK(std::abs(rep[1] - f.tail<2>().dot(Pos(-n.y(), n.x()))) < 1e-12);
    CHECK(std::abs(rep[2] - (0.6 * rep[0] - std::abs(rep[1]))) < 1e-12);
  }
}

TEST_CASE("two fingers: constraint forces do no work, a static hold holds with the forces asked for") {
  // Two 2-link fingers (bases at x = ∓0.06) hold a 0.06 × 0.04 box at its side mid-points.
  MechanismModel<Planar> d;
  for (double x : {-0.06, 0.06}) {
    const int base = addLink(d.tree, -1, Pos(x, 0), 0.10, 0.20);
    addLink(d.tree, base, Pos(0.10, 0), 0.08, 0.15);
  }
  d.tree.gravity = kGravity;
  Payload box;
  box.mass = 0.2;
  box.inertia = 0.2 * (0.06 * 0.06 + 0.04 * 0.04) / 12;
  box.pose0 = {0, 0, 0.14};
  d.payloads.push_back(box);
  d.constraints.push_back(std::make_shared<PointContact<Planar>>(BodyRef::link(1), Pos(0.08, 0), BodyRef::payload(0), Pos(-0.03, 0), Pos(-1, 0), 0.6));
  d.constraints.push_back(std::make_shared<PointContact<Planar>>(BodyRef::link(3), Pos(0.08, 0), BodyRef::payload(0), Pos(0.03, 0), Pos(1, 0), 0.6));
  ConstrainedMechanism<Planar> mech(d);
  // An assembled configuration: elbow-up guesses, then projection onto φ = 0.
  VecN q(7), v = VecN::Zero(7);
  q << 1.9, -1.2, 1.25, 1.2, 0.0, 0.0, 0.14;
  REQUIRE(projectPositions(mech, DriftOptions{}, q));
  REQUIRE(mech.residual(q) < 1e-12);

  SUBCASE("no work along the free motion: ηᵀ (J θ' − A v_c) = 0 on consistent velocities") {
    Random r;
    for (int trial = 0; trial < 5; ++trial) {
      VecN vv = r.vec(7, 2.0);
      projectVelocities(mech, q, vv);
      const auto s = mech.solve(q, vv, r.vec(4, 1.0));
      VecN phi;
      MatN G;
      mech.constraint(q, phi, G);
      CHECK(std::abs(s.eta.dot(G * vv)) < 1e-10 * std::max(1.0, s.eta.norm()));
      // The object's Newton–Euler: M_c α_c + G_c = Σ Aᵀ f from the reported forces (at the contacts).
      Eigen::Vector3d wrench(0, 0, -box.mass * 9.81);
      for (int i = 0; i < 2; ++i) {
        const Planar::Vec f = mech.constraintForce(i, s);
        const Pos p = mech.model().constraints[std::size_t(i)]->point(mech.kinematics());
        const Pos rel = p - Pos(q[5], q[6]);
        wrench += Eigen::Vector3d(f[0] + Planar::crossScalar(rel, f.tail<2>()), f[1], f[2]);
      }
      CHECK(std::abs(box.inertia * s.alpha_c[0] - wrench[0]) < 1e-9);
      CHECK(std::abs(box.mass * s.alpha_c[1] - wrench[1]) < 1e-9);
      CHECK(std::abs(box.mass * s.alpha_c[2] - wrench[2]) < 1e-9);
    }
  }
  SUBCASE("static hold: τ = G + Jᵀ f with the object's weight shared and a squeeze gives zero accelerations") {
    // Contact forces on the box (a on b): each carries half the weight W/2, and they squeeze by σ along
    // the line joining the contacts (the internal force: it moves nothing, the contacts being symmetric
    // about the centre of mass).
    const double half = 0.5 * box.mass * 9.81, squeeze = 2.0;
    mech.stage(q);
    const Pos p1 = mech.model().constraints[0]->point(mech.kinematics()), p2 = mech.model().constraints[1]->point(mech.kinematics());
    const Pos u = (p2 - p1).normalized();
    const Eigen::Vector2d f1 = Pos(0, half) + squeeze * u, f2 = Pos(0, half) - squeeze * u;
    const VecN G = mech.gravityTorque(q);
    VecN tau(4);
    for (int finger = 0; finger < 2; ++finger) {
      MatN J;
      VecN unused;
      mech.pointJacobian(2 * finger + 1, Pos(0.08, 0), q, v, J, unused);
      const Eigen::Vector2d& f = finger == 0 ? f1 : f2;
      const VecN t = J.bottomRows(2).transpose() * f;
      tau.segment(2 * finger, 2) = G.segment(2 * finger, 2) + t.segment(2 * finger, 2);
    }
    const auto s = mech.solve(q, v, tau);
    CHECK(s.qdd.norm() < 1e-9);
    CHECK(s.alpha_c.norm() < 1e-9);
    CHECK((mech.constraintForce(0, s).tail<2>() - f1).norm() < 1e-9);
    CHECK((mech.constraintForce(1, s).tail<2>() - f2).norm() < 1e-9);
    double rep[3];
    mech.constraintReport(0, s, rep);
    CHECK(std::abs(rep[0] - (squeeze + half * u.y())) < 1e-9);  // pressing into the box's left face (n = −u)
    CHECK(std::abs(rep[1] + half * u.x()) < 1e-9);             // t = ẑ × n: f_t = −(W/2)·(u_x)
  }
  SUBCASE("passive (τ = 0, RK4 + projection, 1 s): energy conserved to RK4's order, on φ = 0") {
    // The light fingers let the box fall and fold fast (T up to ~0.1 J in 1 s): at 1 ms RK4 leaves
    // |ΔE| ~ 2e-5 of T_max; halving dt divides it by ~16-20 (fourth order, measured 20.4 and 18.5), so
    // the error is the integrator's, not the model's.
    const auto [de1, phi1] = passiveRun(mech, q, v, 1.0, 1e-3);
    const auto [de2, phi2] = passiveRun(mech, q, v, 1.0, 5e-4);
    const auto [de4, phi4] = passiveRun(mech, q, v, 1.0, 2.5e-4);
    MESSAGE("two-finger grasp passive: |ΔE|/T_max = ", de1, ", ", de2, ", ", de4, " at dt = 1, 0.5, 0.25 ms; max |φ| = ", phi1);
    CHECK(de1 / de2 > 12);
    CHECK(de2 / de4 > 12);
    CHECK(de4 < 1e-7);
    CHECK(std::max({phi1, phi2, phi4}) < 1e-9);
  }
}

TEST_CASE("passive runs conserve energy: the slider crank, and a spatial arm pinned on a plane") {
  {
    ConstrainedMechanism<Planar, 3, 3, 1> mech(sliderCrank());
    VecN q(4), v = VecN::Zero(4);
    q << 1.0, -1.5, 0.5, 0.4;
    const auto [de, phi] = passiveRun(mech, q, v, 2.0);
    MESSAGE("slider crank passive: |ΔE|/T_max = ", de, ", max |φ| = ", phi);
    CHECK(de < 1e-6);
    CHECK(phi < 1e-9);
  }
  {
    // The spatial test arm with its tip held on the plane z = z0 (one row): a bilateral pen on a table.
    MechanismModel<Spatial> d;
    d.tree = test::spatialArm();
    std::array<bool, 6> rows{};
    rows[5] = true;
    d.constraints.push_back(std::make_shared<PointClosure<Spatial>>(BodyRef::link(2), Spatial::Pos(0.3, 0, 0), BodyRef::world(),
                                                                    Spatial::Pos(0, 0, 0.2), rows));
    ConstrainedMechanism<Spatial> mech(d);
    VecN q(3), v(3);
    q << 0.2, 0.4, 0.3;
    v << 1.0, 0.5, -0.5;
    const auto [de, phi] = passiveRun(mech, q, v, 1.0);
    MESSAGE("spatial arm on a plane: |ΔE|/T_max = ", de, ", max |φ| = ", phi);
    CHECK(de < 1e-6);
    CHECK(phi < 1e-9);
  }
}

TEST_CASE("a spatial pin's rows are exactly a weld's translation rows (the pin's own linear-only path)") {
  // A pin (no rotation row) skips the rotation vector and the angular rows of its Jacobian and bias;
  // those rows must be the bits the weld computes for the same points, at random states.
  MechanismModel<Spatial> d;
  d.tree = test::spatialArm();
  const Spatial::Pos pa(0.3, 0.02, -0.01), pb(0.05, 0.1, 0.15);
  std::array<bool, 6> xz{};
  xz[3] = xz[5] = true;
  const PointClosure<Spatial> weld(BodyRef::link(2), pa, BodyRef::link(0), pb, PointClosure<Spatial>::all());
  const PointClosure<Spatial> pin(BodyRef::link(2), pa, BodyRef::link(0), pb, PointClosure<Spatial>::translations());
  const PointClosure<Spatial> pin_xz(BodyRef::link(2), pa, BodyRef::link(0), pb, xz);
  TreeData<Spatial> data(d.tree);
  MechanismKinematics<Spatial> k;
  k.model = &d;
  k.tree = &data;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 20; ++trial) {
    VecN q(3), v(3);
    for (int i = 0; i < 3; ++i) q[i] = u(rng), v[i] = u(rng);
    worldKinematics(d.tree, q, data);
    Eigen::MatrixXd M(3, 3);
    Eigen::VectorXd h(3);
    crbaWorld(d.tree, data, M);
    biasForcesWorld(d.tree, data, v, h);
    VecN phi6 = VecN::Zero(6), phi3 = VecN::Zero(3), phi2 = VecN::Zero(2), b6(6), b3(3), b2(2);
    MatN J6 = MatN::Zero(6, 3), J3 = MatN::Zero(3, 3), J2 = MatN::Zero(2, 3), A6(6, 0), A3(3, 0), A2(2, 0);
    weld.position(k, 0, phi6, J6, A6);
    pin.position(k, 0, phi3, J3, A3);
    pin_xz.position(k, 0, phi2, J2, A2);
    weld.bias(k, 0, b6);
    pin.bias(k, 0, b3);
    pin_xz.bias(k, 0, b2);
    CHECK(phi3 == phi6.tail(3));
    CHECK(J3 == J6.bottomRows(3));
    CHECK(b3 == b6.tail(3));
    CHECK(phi2 == Eigen::Vector2d(phi6[3], phi6[5]));
    CHECK(J2.row(0) == J6.row(3));
    CHECK(J2.row(1) == J6.row(5));
    CHECK(b2 == Eigen::Vector2d(b6[3], b6[5]));
    CHECK(J3.norm() > 0.1);  // the rows are not trivially zero
    CHECK(b3.norm() > 1e-3);
  }
}

TEST_CASE("descriptions that cannot work are refused with a sentence") {
  MechanismModel<Planar> d = sliderCrank();
  d.payloads[0].mass = 0;
  CHECK_THROWS_WITH_AS(ConstrainedMechanism<Planar>{d}, doctest::Contains("positive mass"), std::invalid_argument);
  d = sliderCrank();
  d.constraints.push_back(std::make_shared<PointClosure<Planar>>(BodyRef::link(7), Pos::Zero(), BodyRef::world(), Pos::Zero(),
                                                                 PointClosure<Planar>::all()));
  CHECK_THROWS_WITH_AS(ConstrainedMechanism<Planar>{d}, doctest::Contains("names a body"), std::invalid_argument);
  CHECK_THROWS_WITH_AS((ConstrainedMechanism<Planar, 3, 2, 1>{sliderCrank()}), doctest::Contains("do not match"), std::invalid_argument);
}

TEST_CASE("joint springs and friction in h: the damped oscillator's closed form, spring energy conserved") {
  // One link about z, no gravity, I about the joint: I θ'' + b θ' + k (θ − θ_r) = 0 from θ(0) = θ_r + a:
  // θ(t) = θ_r + a e^{−ζω t}(cos ω_d t + ζω/ω_d sin ω_d t), ω = √(k/I), ζω = b/(2I), ω_d = √(ω² − (ζω)²).
  MechanismModel<Planar> d;
  addLink(d.tree, -1, Pos::Zero(), 0.5, 2.0);
  const double I = 2.0 * 0.25 / 3, k = 3.0, rest = 0.2, a = 0.3;
  for (double b : {0.0, 0.1}) {
    CAPTURE(b);
    d.joints = {JointProperties{k, rest, b, 0.0, 1e-2}};
    ConstrainedMechanism<Planar> mech(d);
    StepOptions o;
    o.drift.kind = Drift::None;
    VecN q(1), v(1);
    q << rest + a;
    v << 0.0;
    const double e0 = mech.energy(q, v), w = std::sqrt(k / I), zw = b / (2 * I), wd = std::sqrt(w * w - zw * zw);
    double err = 0, de = 0;
    for (int n = 1; n <= 3000; ++n) {
      REQUIRE(step(mech, o, VecN::Zero(1), q, v));
      const double t = n * o.dt;
      err = std::max(err, std::abs(q[0] - (rest + a * std::exp(-zw * t) * (std::cos(wd * t) + zw / wd * std::sin(wd * t)))));
      de = std::max(de, std::abs(mech.energy(q, v) - e0));
    }
    MESSAGE("b = ", b, ": max |θ − closed form| = ", err, ", max |E − E0| = ", de, " J (E0 = ", e0, ")");
    CHECK(err < 1e-10);  // RK4 at 1 ms on a 2 rad/s oscillator
    if (b == 0.0) CHECK(de < 1e-10 * e0);  // ½ k (θ − θ_r)² is in the energy
    else CHECK(de > 1e-3 * e0);            // and viscous friction really dissipates
  }
  SUBCASE("Coulomb friction: a torque below F_c creeps at w atanh(τ / F_c) inside the smoothing width (F_c tanh(θ'/w))") {
    d.joints = {JointProperties{0.0, 0.0, 0.0, 2.0, 1e-2}};
    ConstrainedMechanism<Planar> mech(d);
    VecN q = VecN::Zero(1), v = VecN::Zero(1), tau(1);
    tau << 0.5;
    for (int n = 0; n < 2000; ++n) REQUIRE(step(mech, StepOptions{}, tau, q, v));
    CHECK(std::abs(v[0] - 1e-2 * std::atanh(0.5 / 2.0)) < 1e-9);
  }
}

TEST_CASE("what controllers read: inverse dynamics, M, G and Λ = (J M⁻¹ Jᵀ)⁻¹") {
  ConstrainedMechanism<Planar> mech(sliderCrank());
  Random r;
  for (int trial = 0; trial < 5; ++trial) {
    const VecN q = r.vec(3, 2.0), qd = r.vec(3, 2.0), qdd = r.vec(3, 2.0);
    const MatN M = mech.massMatrix(q);
    const VecN h = mech.inverseDynamics(q, qd, VecN::Zero(3));
    CHECK((mech.inverseDynamics(q, qd, qdd) - (M * qdd + h)).norm() < 1e-12 * std::max(1.0, h.norm()));
    CHECK((mech.gravityTorque(q) - mech.inverseDynamics(q, VecN::Zero(3), VecN::Zero(3))).norm() < 1e-12);
    MatN J;
    VecN Jdot;
    mech.pointJacobian(2, Pos(0.2, 0), q, qd, J, Jdot);
    const MatN Jt = J.bottomRows(2);
    const MatN Lambda = mech.operationalInertia(q, Jt);
    const MatN direct = (Jt * M.inverse() * Jt.transpose()).inverse();
    CHECK((Lambda - direct).norm() < 1e-9 * direct.norm());
  }
  // A task Jacobian with dependent rows has no Λ.
  MatN Jbad(2, 3);
  Jbad << 1, 2, 3, 2, 4, 6;
  CHECK(mech.operationalInertia(VecN::Zero(3), Jbad).size() == 0);
}
