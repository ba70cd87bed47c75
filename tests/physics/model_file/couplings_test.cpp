// A file's joint and fixed-tendon equalities as coupling rows (physics/constraints/coupling.h,
// physics/model_file/joint_elements.cpp), its ref / springref / stiffness, and what dynlab refuses about
// tendons, on dynlab's own test models (tests/physics/model_file/models/):
//  * a gripper whose fingers a fixed-tendon equality couples (as the Panda's and the Robotiq 2F-85's
//    are), and two pendulums coupled by a polycoef joint equality: every row's residual at the
//    projection's level; the motion MuJoCo's own simulation of the file makes, to its soft equality's
//    and Euler's error;
//  * ref, springref and stiffness: MuJoCo's own acceleration from a displaced rest (its passive force)
//    equals the hand engine's;
//  * spatial tendons, muscles, tendon limits, a coupling that does not hold at the reference pose: one
//    line naming the element and what is supported (tendon actuators and springs: model_file_tendons_test).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "labs/generic/model_run.h"
#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/constraints/coupling.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

namespace dyn {
using namespace test_model_file;

namespace {

std::string testModel(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/" + name; }

// Hand (labs' stepping, RK4 + projection) and MuJoCo (mj_step, Euler) from the file's pose at rest, dt:
// the largest |q_hand − q_mujoco|∞, the hand's largest residual over every row and its largest |Δq|.
struct Compared {
  double gap = 0, residual = 0, motion = 0;
  VecN last;
};
Compared compare(const model_file::LoadedModel& m, double dt, double duration) {
  Compared c;
  const int n = int(m.q0.size());
  ConstrainedMechanism<Spatial> engine(m.mechanism), desc(m.mechanism);
  model_file::MujocoSimulation mj(m, dt);
  mj.reset(m.q0, VecN::Zero(n));
  VecN q = m.q0, v = VecN::Zero(n), qm, vm;
  const VecN tau = VecN::Zero(n);
  StepOptions o;
  o.dt = dt;
  for (int k = 0, steps = int(std::lround(duration / dt)); k < steps; ++k) {
    engine.updateContacts(q, v, tau);
    REQUIRE(engine.stepLocatingContacts(o, tau, q, v));
    REQUIRE(mj.step());
    mj.state(qm, vm);
    c.gap = std::max(c.gap, (q - qm).cwiseAbs().maxCoeff());
    c.residual = std::max(c.residual, app::elementResidual(m, desc, q, v));
    c.motion = std::max(c.motion, (q - m.q0).cwiseAbs().maxCoeff());
  }
  c.last = q;
  return c;
}

// Bullet stepped passive `steps` times: the largest |coupling(q)| and |moved(q)| on the way.
template <class F, class G>
std::pair<double, double> bulletRun(bullet::BulletMechanism<Spatial>& bt, int n, int steps, F coupling, G moved) {
  VecN q, v;
  double worst = 0, motion = 0;
  for (int k = 0; k < steps; ++k) {
    bt.step(VecN::Zero(n));
    bt.state(q, v);
    worst = std::max(worst, std::abs(coupling(q)));
    motion = std::max(motion, std::abs(moved(q)));
  }
  return {worst, motion};
}

std::string refusal(const std::string& name, const std::string& text) {
  static const std::filesystem::path dir = scratchFolder("couplings");
  return errorOf(writeFile(dir, name, text));
}

}  // namespace

TEST_CASE("a gripper's fingers coupled by a fixed-tendon equality move together, as in MuJoCo") {
  const model_file::LoadedModel m = model_file::load(testModel("tendon_gripper.xml"));
  const auto it = std::find_if(m.contacts.begin(), m.contacts.end(), [](const auto& c) { return c.kind == "tendon_coupling"; });
  REQUIRE(it != m.contacts.end());
  CHECK(it->name == "fingers_together");
  CHECK(m.dof == 2);  // wrist and the finger pair
  // 0.4 s at 0.1 ms: the wrist swings down, the heavier finger slides out onto its stop.
  const Compared c = compare(m, 1e-4, 0.4);
  MESSAGE("gripper: max |q_hand − q_MuJoCo| " << c.gap << " (motion " << c.motion << "), residual " << c.residual << ", q(end) "
                                              << c.last.transpose());
  CHECK(c.motion > 0.5);
  CHECK(std::abs(c.last[1] + c.last[2]) < 1e-12);  // left + right held at its reference length, 0
  CHECK(c.last[1] > 0.04 - 1e-12);                 // the heavy finger out on its stop
  CHECK(c.residual < 1e-12);
  // MuJoCo's equality and limits are soft (solref 0.02 s): its fingers lag the rigid coupling by
  // ~ a/k with k ≈ 2770 s⁻², and Euler's error is O(dt); both stay far below the motion.
  CHECK(c.gap < 0.02 * c.motion);
  // The tendon over two slides held to its length is linear in two joints: a Bullet gear (left + right
  // = 0) holds it too, to its first order (it was refused).
  bullet::BulletMechanism<Spatial> bt(m.mechanism, 1e-4, m.q0, VecN::Zero(3));
  CHECK(bt.describe().find("1 btMultiBodyGearConstraint") != std::string::npos);
  const auto [worst, slid] = bulletRun(bt, 3, 4000, [](const VecN& q) { return q[1] + q[2]; }, [](const VecN& q) { return q[1]; });
  MESSAGE("Bullet's gear on the tendon: max |left + right| " << worst << " m as a finger slid " << slid << " m");
  CHECK(slid > 0.02);
  CHECK(worst < 2e-2 * slid);
}

TEST_CASE("a polycoef joint equality holds b − b0 = 0.5 s + 0.3 s² (s = a − a0) through the motion, as in MuJoCo") {
  const model_file::LoadedModel m = model_file::load(testModel("polycoef_pair.xml"));
  REQUIRE(m.contacts.size() == 1);
  CHECK(m.contacts[0].kind == "joint_coupling");
  CHECK(m.q0[0] == 0.2);  // ref: the pose as written is q = ref
  CHECK(m.dof == 1);
  const Compared c = compare(m, 1e-4, 0.4);
  const double s = c.last[0] - 0.2, b = c.last[1];
  MESSAGE("polycoef: max |q_hand − q_MuJoCo| " << c.gap << " (motion " << c.motion << "), residual " << c.residual);
  CHECK(c.motion > 0.5);
  CHECK(std::abs(b - (0.5 * s + 0.3 * s * s)) < 1e-12);
  CHECK(c.residual < 1e-12);
  CHECK(c.gap < 0.02 * c.motion);
  // Not linear: no Bullet gear holds it, and the builder says so in one line.
  CHECK_THROWS_WITH_AS(bullet::BulletMechanism<Spatial>(m.mechanism, 1e-4, m.q0, VecN::Zero(2)),
                       doctest::Contains("linear coupling of two joints only"), std::invalid_argument);
}

TEST_CASE("a coupling's J is φ's gradient and its bias is J'θ' (central differences, a quartic over a tendon of two joints)") {
  // s₁ = θ₀ − 0.3 θ₂ (a tendon), s₂ = 2 θ₁ + θ₂, P = 0.5 s + 0.3 s² − 0.2 s³ + 0.1 s⁴, about θ_ref.
  VecN ref(3);
  ref << 0.1, -0.2, 0.3;
  const Coupling c("tendon_coupling", {{0, 1.0}, {2, -0.3}}, {{1, 2.0}, {2, 1.0}}, {0, 0.5, 0.3, -0.2, 0.1}, ref);
  MechanismKinematics<Spatial> k;
  auto phiAt = [&](const VecN& q) {
    k.theta = q;
    VecN phi = VecN::Zero(1);
    MatN J = MatN::Zero(1, 3), A = MatN::Zero(1, 0);
    c.position(k, 0, phi, J, A);
    return std::pair{phi[0], VecN(J.row(0).transpose())};
  };
  Random rnd;
  const double h = 1e-5;
  for (int s = 0; s < 4; ++s) {
    const VecN q = ref + rnd.vec(3, 0.8), v = rnd.vec(3, 2.0);
    const auto [phi, J] = phiAt(q);
    VecN fd(3);
    for (int i = 0; i < 3; ++i) {
      VecN e = VecN::Zero(3);
      e[i] = h;
      fd[i] = (phiAt(q + e).first - phiAt(q - e).first) / (2 * h);
    }
    CHECK((fd - J).cwiseAbs().maxCoeff() < 1e-8);
    // J'θ' = d/dt (J θ') along θ' held: (J(q + v h) − J(q − v h)) · v / 2h.
    const double jdot_v = (phiAt(q + h * v).second - phiAt(q - h * v).second).dot(v) / (2 * h);
    k.theta = q, k.theta_rate = v;
    VecN b = VecN::Zero(1);
    c.bias(k, 0, b);
    CHECK(std::abs(b[0] - jdot_v) < 1e-6 * (1 + std::abs(jdot_v)));
  }
  CHECK(!c.linearPair());
}

TEST_CASE("a linear joint equality is a Bullet gear: Bullet keeps the coupling") {
  const std::filesystem::path file = writeFile(scratchFolder("couplings_gear"), "mirror.xml", R"(<mujoco><option><flag contact="disable"/></option><worldbody>
    <body name="a" pos="0 0 1"><joint name="a" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1"/></body>
    <body name="b" pos="0 0.2 1"><joint name="b" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02" mass="0.5"/></body>
  </worldbody><equality><joint joint1="b" joint2="a" polycoef="0 -0.5 0 0 0"/></equality></mujoco>)");
  const model_file::LoadedModel m = model_file::load(file.string());
  bullet::BulletMechanism<Spatial> bt(m.mechanism, 1e-3, m.q0, VecN::Zero(2));
  CHECK(bt.describe().find("btMultiBodyGearConstraint") != std::string::npos);
  const auto [worst, motion] = bulletRun(bt, 2, 400, [](const VecN& q) { return q[1] + 0.5 * q[0]; }, [](const VecN& q) { return q[0]; });
  MESSAGE("Bullet gear: max |b + 0.5 a| " << worst << " over a swing of " << motion << " rad");
  CHECK(motion > 0.5);
  CHECK(worst < 1e-3 * motion);
}

TEST_CASE("ref, springref and stiffness: MuJoCo's own acceleration from a displaced rest equals the hand engine's") {
  // A hinge written at ref 0.3 (its pose as written), its spring's rest at springref 0.5, and a slide
  // with ref and springref of its own: MuJoCo's passive force −k (q − springref) and dynlab's
  // JointProperties must agree, and q0 must be ref.
  const std::string dir = scratchFolder("springs").string();
  const std::filesystem::path file = writeFile(dir, "springs.xml", R"(<mujoco><compiler angle="radian"/><option gravity="0 0 -9.81"><flag contact="disable"/></option><worldbody>
    <body name="a" pos="0 0 1"><joint name="a" type="hinge" axis="0 1 0" ref="0.3" springref="0.5" stiffness="4"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1"/>
      <body name="b" pos="0.3 0 0"><joint name="b" type="slide" axis="1 0 0" ref="0.05" springref="-0.1" stiffness="30"/>
        <geom type="box" size="0.02 0.02 0.02" mass="0.4"/></body></body>
  </worldbody></mujoco>)");
  const model_file::LoadedModel m = model_file::load(file.string());
  CHECK(m.q0[0] == 0.3);
  CHECK(m.q0[1] == 0.05);
  REQUIRE(m.mechanism.joints.size() == 2);
  CHECK(m.mechanism.joints[0].rest == 0.5);
  CHECK(m.mechanism.joints[1].rest == -0.1);
  // One Euler step of MuJoCo from rest (no damping: v1 = dt q̈ exactly) at seeded poses.
  const double dt = 1e-3;
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  model_file::MujocoSimulation mj(m, dt);
  Random rnd;
  double worst = 0;
  for (int s = 0; s < 4; ++s) {
    const VecN q = m.q0 + rnd.vec(2, 0.4), zero = VecN::Zero(2);
    mj.reset(q, zero);
    REQUIRE(mj.step());
    VecN q1, v1;
    mj.state(q1, v1);
    const VecN qdd = mech.solve(q, zero, zero).qdd;
    worst = std::max(worst, (v1 / dt - qdd).cwiseAbs().maxCoeff() / (1 + qdd.cwiseAbs().maxCoeff()));
  }
  CHECK(worst < 1e-9);
}

TEST_CASE("tendons and actuators dynlab cannot hold are refused in one line naming them") {
  const std::string body = R"(<worldbody><body name="a" pos="0 0 1"><joint name="a" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="1" contype="0" conaffinity="0"/><site name="s1"/>
      <body name="b" pos="0.3 0 0"><joint name="b" type="hinge" axis="0 1 0"/><geom type="sphere" size="0.02" mass="0.5" contype="0" conaffinity="0"/>
      <site name="s2"/></body></body></worldbody>)";
  auto file = [&](const std::string& rest) { return "<mujoco>" + body + rest + "</mujoco>"; };
  const std::string fixed = R"(<tendon><fixed name="t"><joint joint="a" coef="1"/><joint joint="b" coef="-1"/></fixed></tendon>)";
  CHECK(refusal("spatial.xml", file(R"(<tendon><spatial name="cable"><site site="s1"/><site site="s2"/></spatial></tendon>)"))
            .find("tendon 'cable' is a spatial tendon") != std::string::npos);
  CHECK(refusal("muscle.xml", file(R"(<actuator><muscle name="biceps" joint="a" lengthrange="0.1 1"/></actuator>)")).find("actuator 'biceps' is a muscle") !=
        std::string::npos);
  CHECK(refusal("ranged.xml", file(R"(<tendon><fixed name="t" limited="true" range="-1 1"><joint joint="a" coef="1"/></fixed></tendon>)"))
            .find("tendon 't' has a range") != std::string::npos);
  CHECK(refusal("offset.xml", file(R"(<equality><joint name="e" joint1="b" joint2="a" polycoef="0.1 1 0 0 0"/></equality>)"))
            .find("equality 'e' has polycoef[0] = 0.1") != std::string::npos);
  // A fixed tendon just defined (the Panda's "split", read by its actuator) loads and holds nothing.
  static const std::filesystem::path dir = scratchFolder("couplings_defined");
  const model_file::LoadedModel m = model_file::load(writeFile(dir, "defined.xml", file(fixed)).string());
  CHECK(m.contacts.empty());
  CHECK(m.dof == 2);
  // A ball joint's spring is refused, the line naming what dynlab reads and what to change.
  CHECK(refusal("ball.xml", R"(<mujoco><worldbody><body name="a"><joint name="shoulder" type="ball" stiffness="2"/><geom type="sphere" size="0.1" mass="1"/>
    </body></worldbody></mujoco>)")
            .find("joint 'shoulder' (body 'a') is a ball joint with stiffness 2; dynlab holds springs on hinge and slide joints only") != std::string::npos);
}

}  // namespace dyn
