// Fixed tendons that drive and pull (physics/model_file: controls.cpp, joint_elements.cpp, actuators.cpp;
// issue 40 item 5), on tendon_fingers.xml, written as the Menagerie's Panda and Robotiq 2F-85 are (an
// actuator on the fingers' tendon 'split'), against MuJoCo's own:
//  * the actuator on a tendon puts gear · coef_k · force on each finger, MuJoCo's qfrc_actuator (clamps
//    included); a tendon's own stiffness and damping are MuJoCo's qfrc_passive;
//  * from the keyframe, the hand engine's RK4 run is MuJoCo's RK4 run to rounding (and parts from it at
//    once without the tendons' forces);
//  * a tendon's frictionloss is read and noted (Coulomb smoothed as a joint's); a tendon limit stays
//    refused in one line, and so does a coefficient past ±1e9.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "physics/model_file/actuators.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"
#include "tests/physics/model_file/rk4_compare.h"

using namespace dyn;
using namespace dyn::test_model_file;

namespace {

std::string fingers() { return std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/files/tendon_fingers.xml"; }

}  // namespace

TEST_CASE("tendon_fingers.xml: an actuator on a fixed tendon and the tendon's own spring and damper as MuJoCo applies them") {
  const model_file::LoadedModel m = model_file::load(fingers());
  REQUIRE(m.actuators.size() == 2);
  const model_file::Actuator& split = m.actuators[0];
  CHECK(split.tendon == "split");
  CHECK(split.joint.empty());
  CHECK(split.path == std::vector<model_file::TendonTerm>{{1, 0.5}, {2, 0.5}});
  CHECK(m.actuators[1].joint == "wrist");
  REQUIRE(m.tendons.size() == 1);  // 'split' has no forces of its own
  CHECK(m.tendons[0].name == "sync");
  CHECK(m.tendons[0].path == std::vector<model_file::TendonTerm>{{1, 1.0}, {2, -1.0}});
  CHECK(m.tendons[0].stiffness == 40);
  CHECK(m.tendons[0].rest == 0.01);
  CHECK(m.tendons[0].damping == 0.5);
  CHECK(m.notes.empty());  // every tendon is read by something
  model_file::MujocoReference mj(m);
  Random r;
  double actuation = 0, passive = 0, largest = 0, pull = 0;
  for (int s = 0; s < 20; ++s) {
    VecN q = r.vec(3, 0.05), v = r.vec(3, 1.0), ctrl = r.vec(2, 1.0);
    ctrl[0] = 160 + 120 * ctrl[0];  // past the range's end (255) too
    const VecN ours = model_file::actuatorTorques(m.actuators, ctrl, q, v);
    actuation = std::max(actuation, (ours - mj.actuation(q, v, ctrl)).cwiseAbs().maxCoeff());
    largest = std::max(largest, ours.tail(2).cwiseAbs().maxCoeff());
    const VecN spring = model_file::tendonTorques(m.tendons, q, v);
    passive = std::max(passive, (spring - mj.passive(q, v)).cwiseAbs().maxCoeff());
    pull = std::max(pull, spring.cwiseAbs().maxCoeff());
  }
  CHECK(largest > 1);
  CHECK(pull > 0.5);
  CHECK(actuation < 1e-12);
  CHECK(passive < 1e-12);
  // One force on the tendon, half on each finger: at rest with the fingers shut, ctrl 255 pulls
  // 0.0156863 · 255 = 4 N, 2 N on each; ctrl 300 the same (clamped to the range).
  const VecN zero = VecN::Zero(3);
  VecN full(2), past(2);
  full << 255, 0;
  past << 300, 0;
  const VecN tau = model_file::actuatorTorques(m.actuators, full, zero, zero);
  CHECK(tau[1] == doctest::Approx(0.5 * 0.0156863 * 255));
  CHECK(tau[2] == tau[1]);
  CHECK(model_file::actuatorTorques(m.actuators, past, zero, zero) == tau);
  // The model's drive is both: the actuators at its ctrl and the tendons.
  CHECK(model_file::actuatorTorques(m, zero, zero) == model_file::actuatorTorques(m.actuators, m.ctrl, zero, zero) + model_file::tendonTorques(m.tendons, zero, zero));
}

TEST_CASE("tendon_fingers.xml from keyframe 'grip': the hand engine's RK4 run is MuJoCo's RK4 run to rounding") {
  model_file::LoadOptions o;
  o.key = "grip";
  const model_file::LoadedModel m = model_file::load(fingers(), o);
  CHECK(m.ctrl[0] == 200);
  // Measured 7.1e-15 over 1 s: the tendon laws evaluated at each stage as MuJoCo evaluates them; without
  // them (the actuators and the tendon spring) the fingers move apart from MuJoCo's at once.
  const double apart = rk4Difference(m, 1e-3, 1000);
  MESSAGE("max |q_hand - q_mujoco| over 1 s at RK4: ", apart);
  CHECK(apart < 1e-12);
  CHECK(rk4Difference(m, 1e-3, 1000, false) > 1e-3);
  model_file::LoadedModel no_spring = m;
  no_spring.tendons.clear();
  CHECK(rk4Difference(no_spring, 1e-3, 1000) > 1e-4);
}

TEST_CASE("a tendon's frictionloss is read as smoothed Coulomb friction and noted; a tendon limit is one line") {
  static const std::filesystem::path dir = scratchFolder("tendons");
  const std::string arm = R"(<mujoco><worldbody><body name="a"><joint name="a" axis="0 1 0"/><geom size="0.1" contype="0" conaffinity="0"/>
      <body name="b" pos="0.3 0 0"><joint name="b" axis="0 1 0"/><geom size="0.1" contype="0" conaffinity="0"/></body></body></worldbody>)";
  const std::string dragged = arm + R"(<tendon><fixed name="drag" frictionloss="0.2"><joint joint="a" coef="1"/><joint joint="b" coef="2"/></fixed></tendon></mujoco>)";
  const model_file::LoadedModel m = model_file::load(writeFile(dir, "drag.xml", dragged).string());
  REQUIRE(m.tendons.size() == 1);
  CHECK(m.tendons[0].frictionloss == 0.2);
  REQUIRE(m.notes.size() == 1);
  CHECK(m.notes[0] == "tendon 'drag': frictionloss 0.2 read as Coulomb friction smoothed over a rate width of 0.01 (MuJoCo: exact stiction)");
  // Moving fast along the tendon (l' = 1 + 2 · 1 = 3 ≫ 0.01): the whole 0.2 against it, coef on each joint.
  const VecN tau = model_file::tendonTorques(m.tendons, VecN::Zero(2), VecN::Ones(2));
  CHECK(tau[0] == doctest::Approx(-0.2));
  CHECK(tau[1] == doctest::Approx(-0.4));
  const std::string ranged = arm + R"(<tendon><fixed name="t" range="-1 1"><joint joint="a" coef="1"/></fixed></tendon></mujoco>)";
  CHECK(errorOf(writeFile(dir, "ranged.xml", ranged)).find("tendon 't' has a range (limited); dynlab reads fixed tendons") != std::string::npos);
  const std::string huge = arm + R"(<tendon><fixed name="t"><joint joint="a" coef="1e300"/></fixed></tendon></mujoco>)";
  CHECK(errorOf(writeFile(dir, "huge.xml", huge)).find("tendon 't''s coef is 1e+300; dynlab reads finite values") != std::string::npos);
}
