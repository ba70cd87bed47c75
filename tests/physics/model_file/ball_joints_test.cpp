// Ball and free joints (physics/chain.h addBall, physics/model_file/ball_joints.cpp, the integrators'
// quaternion step in physics/integrate.cpp), on dynlab's own test models (models/):
//  * ball_chain.xml, a free body carrying an arm with a ball shoulder, an elbow hinge, and a hand with a
//    hinge then a ball in one body: M and the bias equal MuJoCo's (mj_fullM, qfrc_bias) at random states
//    in MuJoCo's own qpos/qvel layout; RNEA, CRBA, ABA and the world-frame bias agree; the bias passes
//    the energy identity vᵀh = ½ vᵀṀv + U̇ by central differences along q ⊕ t v;
//  * RK4's fourth order with ball joints (errors against a fine reference, halving dt);
//  * hand RK4 against MuJoCo's own RK4 (mj_step, rk4) over 0.5 s;
//  * tumbling_box.xml: a free box spun near its intermediate axis, no gravity: energy, linear and world
//    angular momentum kept to RK4's error, |Q| = 1;
//  * ball_loop.xml: a loop closed through a ball joint keeps every row within 1e-12;
//  * Bullet (physics/bullet/spherical_links.h): the chain and the loop converge to the hand's motion at
//    its first order (the gap halves with Bullet's step).
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/chain_world.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

namespace dyn {
using namespace test_model_file;

namespace {

std::string testModel(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/" + name; }

// A random state in MuJoCo's layout: every quaternion (a ball's qw … qz) a random unit one.
void randomState(const model_file::LoadedModel& m, Random& rnd, VecN& q, VecN& v) {
  q = m.q0 + rnd.vec(int(m.q0.size()), 0.7);
  v = rnd.vec(int(m.joints.size()), 2.0);
  normalizeConfiguration(m.mechanism.tree, q);
}

double relative(const MatN& a, const MatN& b) { return maxAbs(a - b) / std::max(1.0, maxAbs(b)); }

}  // namespace

TEST_CASE("ball and free joints: M and the bias equal MuJoCo's at random states, in MuJoCo's qpos/qvel") {
  const model_file::LoadedModel m = model_file::load(testModel("ball_chain.xml"));
  // root: 7 qpos, 6 qvel; shoulder 4/3; elbow, wrist 1/1; wrist_ball 4/3.
  REQUIRE(m.q0.size() == 17);
  REQUIRE(m.joints.size() == 14);
  CHECK(m.coordinates[3] == "root_qw");
  CHECK(m.joints[6].name == "shoulder_wx");
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  model_file::MujocoReference ref(m);
  Random rnd;
  double dM = 0, dh = 0;
  for (int s = 0; s < 20; ++s) {
    VecN q, v;
    randomState(m, rnd, q, v);
    dM = std::max(dM, relative(mech.massMatrix(q), ref.massMatrix(q)));
    const VecN h = mech.inverseDynamics(q, v, VecN::Zero(v.size()));
    dh = std::max(dh, relative(h, ref.bias(q, v)));
  }
  MESSAGE("ball_chain: max relative |ΔM| " << dM << ", |Δh| " << dh);
  CHECK(dM < 1e-12);
  CHECK(dh < 1e-12);
}

TEST_CASE("ball and free joints: RNEA, CRBA, ABA and the world-frame bias agree; vᵀh = ½ vᵀṀv + U̇") {
  const model_file::LoadedModel m = model_file::load(testModel("ball_chain.xml"));
  const TreeModel<Spatial>& tree = m.mechanism.tree;
  TreeData<Spatial> data(tree);
  Random rnd;
  const int n = tree.dof();
  for (int s = 0; s < 10; ++s) {
    VecN q, v;
    randomState(m, rnd, q, v);
    const VecN qdd = rnd.vec(n, 3.0);
    forwardKinematics(tree, q, v, data);
    const VecN tau = rnea(tree, data, v, qdd), h = rnea(tree, data, v, VecN::Zero(n));
    const MatN M = crba(tree, data);
    CHECK(maxAbs(M * qdd + h - tau) < 1e-11);
    CHECK(maxAbs(aba(tree, data, v, tau) - qdd) < 1e-10);
    VecN hw(n);
    biasForcesWorld(tree, data, v, hw);
    CHECK(maxAbs(hw - h) < 1e-11);
    CHECK(std::abs(0.5 * v.dot(M * v) - kineticEnergy(tree, data)) < 1e-12);
    // Along q(t) = q ⊕ t v: d/dt of vᵀMv/2 at v held is ½ vᵀṀv, and U̇ = vᵀG; together vᵀh.
    const double e = 1e-5;
    auto at = [&](double t, double& U) {
      VecN qt = q;
      integrateConfiguration(tree, qt, v, t);
      positionKinematics(tree, qt, data);
      U = potentialEnergy(tree, data);
      return 0.5 * v.dot(crba(tree, data) * v);
    };
    double Up, Um;
    const double Tp = at(e, Up), Tm = at(-e, Um);
    const double rate = (Tp - Tm + Up - Um) / (2 * e);
    CHECK(std::abs(rate - v.dot(h)) < 1e-6 * (1 + std::abs(rate)));
  }
}

namespace {

// The hand engine (RK4, no drift handling: no loops) from (q, v) for duration at step dt.
VecN runHand(const model_file::LoadedModel& m, VecN q, VecN v, double dt, double duration, Drift drift = Drift::None) {
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  StepOptions o;
  o.dt = dt;
  o.drift.kind = drift;
  const VecN tau = VecN::Zero(v.size());
  for (int k = 0, steps = int(std::lround(duration / dt)); k < steps; ++k) REQUIRE(step(mech, o, tau, q, v));
  return q;
}

// A state that swings every joint: the chain's seeded random state.
void movingState(const model_file::LoadedModel& m, VecN& q, VecN& v) {
  Random rnd;
  randomState(m, rnd, q, v);
}

}  // namespace

TEST_CASE("RK4 keeps its fourth order with ball and free joints (quaternions in the embedding, renormalised)") {
  const model_file::LoadedModel m = model_file::load(testModel("ball_chain.xml"));
  VecN q0, v0;
  movingState(m, q0, v0);
  const double T = 0.2;
  const VecN reference = runHand(m, q0, v0, T / 1600, T);
  double previous = 0;
  for (int steps : {25, 50, 100, 200}) {
    const double err = (runHand(m, q0, v0, T / steps, T) - reference).cwiseAbs().maxCoeff();
    if (previous > 0) {
      MESSAGE(steps << " steps: error " << err << ", ratio " << previous / err << " (16 at fourth order)");
      CHECK(previous / err > 13.0);
      CHECK(previous / err < 19.0);
    }
    previous = err;
  }
}

namespace {

// MuJoCo's own RK4 (mj_step, rk4) from (q0, v0) over T at dt: q at T.
VecN runMujoco(const model_file::LoadedModel& m, const VecN& q0, const VecN& v0, double dt, double T) {
  model_file::MujocoSimulation mj(m, dt, true);
  mj.reset(q0, v0);
  for (int k = 0; k < int(std::lround(T / dt)); ++k) REQUIRE(mj.step());
  VecN q, v;
  mj.state(q, v);
  return q;
}

}  // namespace

TEST_CASE("hand RK4 and MuJoCo's own RK4 agree over 0.5 s with ball and free joints, to MuJoCo's own error") {
  const model_file::LoadedModel m = model_file::load(testModel("ball_chain.xml"));
  VecN q0, v0;
  movingState(m, q0, v0);
  const double dt = 1e-3, T = 0.5;
  // The exact motion, near enough: the hand at dt/10 (its error ~1e-13: fourth order, measured above).
  const VecN exact = runHand(m, q0, v0, dt / 10, T);
  const double hand = (runHand(m, q0, v0, dt, T) - exact).cwiseAbs().maxCoeff();
  const double mj = (runMujoco(m, q0, v0, dt, T) - exact).cwiseAbs().maxCoeff();
  const double mj_half = (runMujoco(m, q0, v0, dt / 2, T) - exact).cwiseAbs().maxCoeff();
  const double gap = (runHand(m, q0, v0, dt, T) - runMujoco(m, q0, v0, dt, T)).cwiseAbs().maxCoeff();
  MESSAGE("at 0.5 s, 1 ms: |q_hand − q_MuJoCo| " << gap << "; errors against the hand at 0.1 ms: hand " << hand << ", MuJoCo " << mj
                                                << " (at 0.5 ms " << mj_half << ": ratio " << mj / mj_half << ")");
  // MuJoCo 2.2.2's RK4 moves each stage's quaternions by the exponential map of the stage's combined
  // rates at the step's start (mj_integratePos), without the correction of the map's derivative: second
  // order in the rotations (the ratio at half the step is ~4, not 16). So the two engines differ by
  // MuJoCo's own error, which halving its step quarters; the hand's stays three orders below it.
  CHECK(hand < 1e-8);
  CHECK(mj / mj_half > 3.5);
  CHECK(mj / mj_half < 4.5);
  CHECK(gap < 1.05 * mj + hand);
  CHECK(gap > 0.95 * mj - hand);
}

TEST_CASE("a free box tumbling without gravity keeps its energy, momenta and unit quaternion") {
  model_file::LoadOptions opt;
  opt.key = "spin";
  const model_file::LoadedModel m = model_file::load(testModel("tumbling_box.xml"), opt);
  const TreeModel<Spatial>& tree = m.mechanism.tree;
  REQUIRE(tree.dof() == 6);
  const auto& body = tree.bodies.back();
  const Eigen::Matrix3d R0 = tree.balls[0].post;
  const Eigen::Vector3d c = body.central.c;
  // World momenta at (q, v): p = m v_c, L = m c × v_c + R Ic ω about the world origin (R: world from the
  // body's dynlab frame, Ic its central inertia there, ω its angular velocity in that frame).
  auto momenta = [&](const VecN& q, const VecN& v, Eigen::Vector3d& p, Eigen::Vector3d& L) {
    const Eigen::Quaterniond Q(q[3], q[4], q[5], q[6]);
    const Eigen::Matrix3d R = Q.normalized().toRotationMatrix() * R0.transpose();
    const Eigen::Vector3d w = R * (R0 * Eigen::Vector3d(v[3], v[4], v[5]));
    const Eigen::Vector3d com = Eigen::Vector3d(q[0], q[1], q[2]) + R * c;
    const Eigen::Vector3d vc = Eigen::Vector3d(v[0], v[1], v[2]) + w.cross(R * c);
    p = body.central.m * vc;
    L = com.cross(p) + R * body.central.Ic * R.transpose() * w;
  };
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  VecN q = m.start_q, v = m.start_v;
  Eigen::Vector3d p0, L0, p, L;
  momenta(q, v, p0, L0);
  const double E0 = mech.energy(q, v);
  StepOptions o;
  o.dt = 1e-3;
  o.drift.kind = Drift::None;
  const VecN tau = VecN::Zero(6);
  double dE = 0, dL = 0, dp = 0, dnorm = 0, turn = 0;
  for (int k = 0; k < 4000; ++k) {
    REQUIRE(step(mech, o, tau, q, v));
    momenta(q, v, p, L);
    dE = std::max(dE, std::abs(mech.energy(q, v) - E0) / E0);
    dL = std::max(dL, (L - L0).norm() / L0.norm());
    dp = std::max(dp, (p - p0).norm() / p0.norm());
    dnorm = std::max(dnorm, std::abs(q.segment<4>(3).norm() - 1.0));
    turn = std::max(turn, std::abs(v[3] - m.start_v[3]));
  }
  MESSAGE("tumbling box, 4 s at 1 ms: |ΔE|/E " << dE << ", |ΔL|/|L| " << dL << ", |Δp|/|p| " << dp << ", ||Q| − 1| " << dnorm
                                                << ", largest change of ω_x " << turn);
  CHECK(turn > 1.0);  // it tumbles: the spin about the intermediate axis does not stay put
  CHECK(dE < 1e-8);
  CHECK(dL < 1e-8);
  CHECK(dp < 1e-10);
  CHECK(dnorm < 1e-15);
}

TEST_CASE("a loop closed through a ball joint keeps every row within 1e-12") {
  const model_file::LoadedModel m = model_file::load(testModel("ball_loop.xml"));
  REQUIRE(m.closures.size() == 1);
  CHECK(m.dof == 2);  // crank, the rod's spin about its own axis
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  model_file::EveryClosureRow every(m);
  VecN q = m.q0, v = VecN::Zero(5);
  StepOptions o;
  o.dt = 1e-3;
  const VecN tau = VecN::Zero(5);
  const double E0 = mech.energy(q, v);
  double residual = 0, motion = 0, dE = 0;
  for (int k = 0; k < 1000; ++k) {
    REQUIRE(step(mech, o, tau, q, v));
    residual = std::max(residual, every.residual(q));
    motion = std::max(motion, std::abs(q[0] - m.q0[0]));
    dE = std::max(dE, std::abs(mech.energy(q, v) - E0));
  }
  MESSAGE("ball loop, 1 s: every row's |φ| " << residual << ", crank motion " << motion << " rad, |ΔE| " << dE << " J");
  CHECK(motion > 0.1);
  CHECK(residual <= 1e-12);
  CHECK(dE < 1e-6);
}

namespace {

// Bullet (semi-implicit Euler, fixed step) from (q0, v0) over T: the largest |q_Bullet − q_hand|∞ over
// the run, the hand at RK4 with projection and the same step (its error ~1e-9: far below Bullet's).
double bulletGap(const model_file::LoadedModel& m, const VecN& q0, const VecN& v0, double dt, double T) {
  bullet::BulletMechanism<Spatial> bt(m.mechanism, dt, q0, v0);
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  StepOptions o;
  o.dt = dt;
  VecN q = q0, v = v0, qb, vb;
  const VecN tau = VecN::Zero(v.size());
  double gap = 0;
  for (int k = 0; k < int(std::lround(T / dt)); ++k) {
    REQUIRE(step(mech, o, tau, q, v));
    bt.step(tau);
    bt.state(qb, vb);
    REQUIRE(qb.size() == q.size());
    gap = std::max(gap, (qb - q).cwiseAbs().maxCoeff());
  }
  return gap;
}

}  // namespace

TEST_CASE("Bullet's spherical links follow the hand engine at Bullet's first order (ball, free joint, a loop)") {
  for (const char* file : {"ball_chain.xml", "ball_loop.xml"}) {
    const model_file::LoadedModel m = model_file::load(testModel(file));
    VecN q0 = m.q0, v0 = VecN::Zero(Eigen::Index(m.joints.size()));
    if (m.closures.empty()) movingState(m, q0, v0);
    // Bullet's own state reads back as written (its kinematics self-check passes at construction).
    bullet::BulletMechanism<Spatial> bt(m.mechanism, 1e-3, q0, v0);
    VecN qb, vb;
    bt.state(qb, vb);
    CHECK(maxAbs(qb - q0) < 1e-12);
    CHECK(maxAbs(vb - v0) < 1e-12);
    const double coarse = bulletGap(m, q0, v0, 1e-3, 0.2), fine = bulletGap(m, q0, v0, 5e-4, 0.2);
    MESSAGE(std::string(file) << ": max |q_Bullet − q_hand| over 0.2 s " << coarse << " at 1 ms, " << fine << " at 0.5 ms (ratio " << coarse / fine << ")");
    CHECK(coarse < 0.05);
    CHECK(coarse / fine > 1.6);
    CHECK(coarse / fine < 2.5);
  }
}

}  // namespace dyn
