// A leg written the way MuJoCo Menagerie's Agility Cassie is (models/leg_loops.xml: a floating pelvis,
// hips with armature, springs with stiffness, an Achilles rod on a ball joint pinned to a heel spring, a
// hinge-only crank – rod – foot loop whose plane the hip turns, a damper on a small crank):
//  * it loads: the planar loop's dependent row turns with the hip, so its rows are chosen at q0 (two of
//    three kept) and checked at assembled poses; the spatial loop keeps all three;
//  * its fastest mode (the crank's damper on the crank and rod) is near RK4's stability edge at the file's
//    0.5 ms, where RK4 no longer follows it: the run takes the sub-steps stiff_steps.h chooses;
//  * at the file's step: |φ| over every row of both loops ≤ 1e-12, MuJoCo's own measure of the loops at
//    the hand's trace too, E − E0 − W at RK4's error; RK4's fourth order at the sub-step (state and books);
//  * Bullet with the same sub-steps stays finite and follows the hand engine;
//  * a four-bar written at a change point (a singular reference pose) is still refused, in one line; so is a
//    chain of more coordinates than kMaxDof.
#include <doctest/doctest.h>

#include <cmath>

#include "fixtures.h"
#include "labs/generic/model_run.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/stiff_steps.h"

namespace dyn::test_model_file {
namespace {

std::string testModel(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/" + name; }

const model_file::Closure& closureNamed(const model_file::LoadedModel& m, const std::string& name) {
  for (const auto& c : m.closures)
    if (c.name == name) return c;
  FAIL("no closure " << name);
  return m.closures.front();
}

// The hand engine from the file's start at a fixed sub-step h (no further sub-steps): q at T and the
// books' largest |E − E0 − W − D| on the way.
struct Reached {
  VecN q;
  double balance = 0;
};
Reached fixedStep(const model_file::LoadedModel& m, double h, double T) {
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  const std::unique_ptr<ConstrainedSystem> engine = model_file::handEngine(m.mechanism);
  StepOptions o;
  o.dt = h;
  VecN q = m.start_q, v = m.start_v;
  const VecN tau = VecN::Zero(v.size());
  const double e0 = mech.energy(q, v);
  double balance = 0;
  for (int k = 0, steps = int(std::lround(T / h)); k < steps; ++k) {
    REQUIRE(step(*engine, o, tau, q, v));
    const Books& b = engine->books();
    balance = std::max(balance, std::abs(mech.energy(q, v) - e0 - b.work - b.friction));
  }
  return {q, balance};
}

}  // namespace

TEST_CASE("a Cassie-style leg loads: the planar loop whose plane the hip turns keeps two rows, the ball loop three") {
  const model_file::LoadedModel m = model_file::load(testModel("leg_loops.xml"));
  REQUIRE(m.closures.size() == 2);
  CHECK(closureNamed(m, "plantar").kept.size() == 2);
  CHECK(closureNamed(m, "plantar").dropped.size() == 1);
  CHECK(closureNamed(m, "achilles").kept.size() == 3);
  // 6 (free) + 3 (hips) + 3 (ball) + 7 hinges, less 5 rows.
  CHECK(m.joints.size() == 19);
  CHECK(m.dof == 14);
  CHECK(m.timestep == 0.0005);
}

TEST_CASE("the leg's fastest mode is near RK4's edge at the file's step; the sub-steps bring it within") {
  const model_file::LoadedModel m = model_file::load(testModel("leg_loops.xml"));
  const model_file::FastestMode mode = model_file::fastestMode(m);
  const int s = model_file::stiffSubsteps(mode.rate, m.timestep);
  MESSAGE("fastest mode |λ| " << mode.rate << " 1/s, mostly " << mode.joint << ": |λ| dt " << mode.rate * m.timestep << ", " << s << " sub-steps");
  // Near RK4's stability edge on the negative real axis (2.785): there one step multiplies the mode by
  // R(−2.66) = 0.83 where it decays by e^−2.66 = 0.07.
  CHECK(mode.rate * m.timestep > 2.5);
  CHECK(mode.rate * m.timestep / s <= model_file::kStiffStep);
  CHECK(mode.rate * m.timestep / (s - 1) > model_file::kStiffStep);  // no more than needed
  CHECK((mode.joint == "foot-crank" || mode.joint == "plantar-rod" || mode.joint == "foot"));
  CHECK(model_file::stiffStepNote(mode, m.timestep).find("'" + mode.joint + "'") != std::string::npos);
  // A slow file keeps one step: the four-bar's run is as it was.
  const model_file::LoadedModel fourbar = model_file::load(model("fourbar.xml"));
  CHECK(model_file::stiffSubsteps(model_file::fastestMode(fourbar).rate, 1e-3) == 1);
}

TEST_CASE("the leg at its file's step: every row of both loops within 1e-12, MuJoCo's own measure too, the books at RK4's error") {
  const model_file::LoadedModel m = model_file::load(testModel("leg_loops.xml"));
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  const double T = 0.3;
  const app::ModelRun run = app::runHand(m, mech, m.timestep, T, VecN::Zero(mech.nv()));
  REQUIRE(run.ok);
  REQUIRE(run.trace.rows() == std::size_t(std::lround(T / m.timestep)) + 1);
  model_file::MujocoReference mj(m);
  double mujoco = 0, moved = 0;
  const int nq = int(m.q0.size());
  for (std::size_t r = 0; r < run.trace.rows(); ++r) {
    VecN q(nq);
    for (int i = 0; i < nq; ++i) q[i] = run.trace.at(r, std::size_t(1 + i));
    mujoco = std::max(mujoco, mj.closure(q));
    moved = std::max(moved, (q - m.q0).cwiseAbs().maxCoeff());
  }
  MESSAGE("0.3 s at 0.5 ms: every row |φ| " << run.residual << ", MuJoCo's measure " << mujoco << ", |E − E0 − W| " << run.balance << " J of E0 "
                                            << run.e0 << " J, kinetic up to " << run.kinetic << " J, max |Δq| " << moved);
  CHECK(moved > 0.3);  // it falls, and its wound springs swing the leg
  CHECK(run.residual <= 1e-12);
  CHECK(mujoco <= 1e-12);
  // Measured: 2.4e-6 J with the 3 sub-steps (then 1.1e-7, 1.0e-8, 8.6e-10 J at 6, 12, 24: RK4's order);
  // one step of 0.5 ms leaves the crank's damped mode barely decaying (R(−2.66) = 0.83 against e^−2.66 =
  // 0.07) and the books 3.2e-3 J off.
  CHECK(run.balance < 1e-5);
}

TEST_CASE("the leg: RK4's fourth order at the sub-step, in the state and in the books") {
  const model_file::LoadedModel m = model_file::load(testModel("leg_loops.xml"));
  const double T = 0.1, h = m.timestep / model_file::stiffSubsteps(model_file::fastestMode(m).rate, m.timestep);
  const Reached reference = fixedStep(m, h / 16, T);
  double previous = 0, previous_balance = 0;
  for (int halvings = 0; halvings < 3; ++halvings) {
    const Reached r = fixedStep(m, h / (1 << halvings), T);
    const double err = (r.q - reference.q).cwiseAbs().maxCoeff(), balance = std::abs(r.balance);
    if (previous > 0) {
      MESSAGE("h/" << (1 << halvings) << ": |Δq| " << err << " (ratio " << previous / err << "), max |E − E0 − W − D| " << balance << " J (ratio "
                   << previous_balance / balance << ")");
      CHECK(previous / err > 10.0);  // 16 at fourth order
      CHECK(previous / err < 24.0);
      CHECK(previous_balance / balance > 8.0);
      CHECK(previous_balance / balance < 32.0);
    }
    previous = err, previous_balance = balance;
  }
}

TEST_CASE("Bullet takes the same sub-steps: the leg stays finite and follows the hand engine at its first order") {
  const model_file::LoadedModel m = model_file::load(testModel("leg_loops.xml"));
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  const double T = 0.1;
  const VecN tau = VecN::Zero(mech.nv());
  const app::ModelRun hand = app::runHand(m, mech, m.timestep, T, tau);
  const app::ModelRun bullet = app::runBullet(m, mech, m.timestep, T, tau);
  REQUIRE(bullet.ok);
  double dq = 0;
  for (std::size_t r = 0; r < std::min(hand.trace.rows(), bullet.trace.rows()); ++r)
    for (int i = 0; i < int(m.q0.size()); ++i) dq = std::max(dq, std::abs(hand.trace.at(r, std::size_t(1 + i)) - bullet.trace.at(r, std::size_t(1 + i))));
  MESSAGE(bullet.summary << ": max |q_hand − q_bullet| " << dq << ", Bullet's every-row |φ| " << bullet.residual);
  CHECK(bullet.trace.rows() == hand.trace.rows());
  CHECK(bullet.summary.find("3 steps of dt/3 per row") != std::string::npos);
  // Measured over 0.3 s: with the sub-steps |φ| 1.7e-4 m and the gap 0.077; at one step of 0.5 ms
  // (Bullet's explicit damper past its edge: |1 − λ dt| = 1.7) 2.7e-3 m and 0.32, the loops' |G v| 2.4 m/s.
  CHECK(bullet.residual < 1e-3);
  CHECK(dq < 0.15);
}

TEST_CASE("a four-bar written at a change point is refused in one line, naming why") {
  const std::string what = errorOf(testModel("straight_fourbar.xml"));
  CHECK(what.find("depend on each other differently from pose to pose") != std::string::npos);
}

TEST_CASE("a chain of more coordinates than kMaxDof is refused in one line, naming the count") {
  std::string bodies, ends;
  for (int i = 0; i <= kMaxDof; ++i) {
    bodies += "<body pos=\"0.1 0 0\"><joint type=\"hinge\" axis=\"0 1 0\"/><geom type=\"sphere\" size=\"0.01\" mass=\"0.1\"/>";
    ends += "</body>";
  }
  const auto file = writeFile(scratchFolder("kmaxdof"), "long_chain.xml",
                              "<mujoco><default><geom contype=\"0\" conaffinity=\"0\"/></default><worldbody>" + bodies + ends + "</worldbody></mujoco>");
  const std::string what = errorOf(file);
  CHECK(what.find(std::to_string(kMaxDof + 1) + " coordinates (qpos), more than dynlab's " + std::to_string(kMaxDof)) != std::string::npos);
}

}  // namespace dyn::test_model_file
