// A model file's actuators, keyframes and collision geoms (physics/model_file: controls.cpp,
// actuators.cpp, contacts.cpp; issue 40 items 3, 4 and 6), against MuJoCo's own:
//  * the torques of servo_arm.xml's position, velocity, general and geared motor actuators equal
//    MuJoCo's qfrc_actuator at seeded states and controls past their ranges (clamps included);
//  * from its keyframe, the hand engine's RK4 run equals MuJoCo's mj_step with RK4 at the same step
//    (the same equations at the same order: only rounding apart), and a control past its range runs
//    as the range's end;
//  * servos too stiff for RK4 at the run's step are named with a step that follows them;
//  * a keyframe that opens a loop, an unknown keyframe and actuators outside the law are one line;
//  * geoms that may collide load, noted once (--ignore-contacts: not noted).
#include <doctest/doctest.h>

#include <string>

#include "physics/constrained_mechanism.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"
#include "tests/physics/model_file/rk4_compare.h"

using namespace dyn;
using namespace dyn::test_model_file;
namespace fs = std::filesystem;

namespace {

std::string testFile(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/files/" + name; }

model_file::LoadedModel loadKey(const std::string& file, const std::string& key) {
  model_file::LoadOptions o;
  o.key = key;
  return model_file::load(file, o);
}

std::string keyError(const std::string& file, const std::string& key) {
  try {
    loadKey(file, key);
  } catch (const model_file::ModelFileError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("servo_arm.xml: position, velocity, general and motor actuators as MuJoCo applies them (qfrc_actuator, clamps included)") {
  const model_file::LoadedModel m = model_file::load(testFile("servo_arm.xml"));
  REQUIRE(m.actuators.size() == 4);
  const model_file::Actuator& pos = m.actuators[0];
  CHECK(pos.name == "shoulder_servo");
  CHECK(pos.joint == "shoulder");
  CHECK(pos.path == std::vector<model_file::TendonTerm>{{0, 1.0}});
  CHECK(pos.gain == 40);
  CHECK(pos.bias[1] == -40);
  CHECK(pos.ctrl_limited);
  CHECK(pos.ctrl_upper == 0.5);
  CHECK(m.actuators[1].gear == 3);
  CHECK(m.actuators[2].bias[2] == -3);
  CHECK(m.actuators[2].force_limited);
  CHECK(m.actuators[3].path == std::vector<model_file::TendonTerm>{{2, 1.0}});
  CHECK(m.actuators[3].gear == 2);
  // At rest from q0 with every control 0 unless a keyframe is chosen.
  CHECK(m.ctrl == VecN::Zero(4));
  CHECK(m.start_q == m.q0);
  model_file::MujocoReference mj(m);
  Random r;
  double worst = 0, largest = 0;
  for (int s = 0; s < 20; ++s) {
    const VecN q = r.vec(3, 1.0), v = r.vec(3, 3.0), ctrl = r.vec(4, 3.0);  // controls past their ranges too
    const VecN ours = model_file::actuatorTorques(m.actuators, ctrl, q, v);
    worst = std::max(worst, (ours - mj.actuation(q, v, ctrl)).cwiseAbs().maxCoeff());
    largest = std::max(largest, ours.cwiseAbs().maxCoeff());
  }
  CHECK(largest > 10);
  CHECK(worst < 1e-12);
  // The clamps: a control past its range acts as the range's end; the velocity servo's force stops at 1.5 N·m.
  const VecN q = VecN::Zero(3), v = VecN::Zero(3);
  VecN past(4), end(4);
  past << 0.9, 5, -1, 0;
  end << 0.5, 1, -1, 0;
  CHECK(model_file::actuatorTorques(m.actuators, past, q, v) == model_file::actuatorTorques(m.actuators, end, q, v));
  CHECK(model_file::actuatorTorques(m.actuators, past, q, v)[0] == doctest::Approx(40 * 0.5 + 3 * 1));
  CHECK(model_file::actuatorTorques(m.actuators, past, q, v)[1] == doctest::Approx(-1.5));
}

TEST_CASE("servo_arm.xml from keyframe 'reach': the hand engine's RK4 run is MuJoCo's mj_step RK4 run to rounding") {
  const model_file::LoadedModel m = loadKey(testFile("servo_arm.xml"), "reach");
  CHECK(m.key == "reach");
  CHECK(m.start_q[1] == -0.4);
  CHECK(m.start_v[1] == 0.5);
  CHECK(m.ctrl[0] == 0.9);  // past the shoulder servo's range: clamped where it acts
  const double dt = 1e-3;
  const int steps = 1000;
  // The same equations at the same order evaluated at the same stages: only rounding apart over 1 s
  // (measured 2.2e-15; rounding of ~1e-16 a step over 1000 steps stays under 1e-12, while a law off
  // by one part in 1e9 of a 20 N·m torque would show above it); without the actuators the runs part at once.
  const double apart = rk4Difference(m, dt, steps);
  MESSAGE("max |q_hand - q_mujoco| over 1 s at RK4: ", apart);
  CHECK(apart < 1e-12);
  CHECK(rk4Difference(m, dt, steps, false) > 1e-2);
  // The clamp in the run: a control at the range's end gives the same run, bit for bit.
  model_file::LoadedModel at_end = m;
  at_end.ctrl[0] = 0.5;
  auto a = model_file::withActuators(model_file::handEngine(m.mechanism), m);
  auto b = model_file::withActuators(model_file::handEngine(at_end.mechanism), at_end);
  StepOptions o;
  o.dt = dt;
  VecN qa = m.start_q, va = m.start_v, qb = qa, vb = va;
  for (int k = 0; k < 200; ++k) {
    REQUIRE(step(*a, o, VecN::Zero(3), qa, va));
    REQUIRE(step(*b, o, VecN::Zero(3), qb, vb));
  }
  CHECK(qa == qb);
  CHECK((qa - m.start_q).cwiseAbs().maxCoeff() > 1e-2);  // it moved
  // The servos' fastest mode (the wrist's 80 N/m and 8 N·s/m on 0.2 kg: about 40 1/s) is within RK4's
  // reach at 1 ms, not at 0.1 s: a note names a step that is.
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  const MatN M = mech.massMatrix(m.start_q);
  CHECK(model_file::stiffServoNote(m, M, 1e-3).empty());
  const std::string stiff = model_file::stiffServoNote(m, M, 0.1);
  CHECK(stiff.find("are stiffer than RK4 follows at dt 0.1 s: the run chatters; pass --dt ") != std::string::npos);
}

TEST_CASE("a four-bar with colliding capsules and a crank servo: keyframes checked against the loop, names listed") {
  const std::string file = testFile("fourbar_servo.xml");
  const model_file::LoadedModel hold = loadKey(file, "hold");
  CHECK(hold.ctrl[0] == 0.3);
  CHECK(hold.keyframes == std::vector<std::string>{"hold", "open"});
  // Collision geoms: loaded, noted once (the default contype/conaffinity let the three links touch).
  int noted = 0;
  for (const std::string& n : hold.notes) noted += n.find("3 geoms collide in MuJoCo but not here (e.g. 'geom #0' and 'geom #2'): dynlab has no geom–geom contact") == 0;
  CHECK(noted == 1);
  const std::string open = keyError(file, "open");
  CHECK(open.rfind(file + ": keyframe 'open': its qpos opens closure 'pin_C' (gap ", 0) == 0);
  const std::string unknown = keyError(file, "home");
  CHECK(unknown == file + ": --key 'home': no such keyframe; the file's keyframes: 'hold', 'open'");
  CHECK(keyError(testFile("servo_arm.xml"), "hold").find("the file's keyframes: 'reach'") != std::string::npos);
  // The servo drives the loop from the keyframe: a hand run keeps the loop closed and moves the crank.
  ConstrainedMechanism<Spatial> mech(hold.mechanism);
  auto engine = model_file::withActuators(model_file::handEngine(hold.mechanism), hold);
  StepOptions o;
  o.dt = 1e-3;
  VecN q = hold.start_q, v = hold.start_v;
  for (int k = 0; k < 300; ++k) REQUIRE(step(*engine, o, VecN::Zero(3), q, v));
  CHECK(mech.residual(q) < 1e-12);
  CHECK(std::abs(q[0]) > 1e-3);
}

TEST_CASE("actuators outside the affine law on a joint, and collision geoms' note: one line each") {
  static const fs::path dir = scratchFolder("actuators");
  const std::string arm = "<mujoco><worldbody><body name=\"b\"><joint name=\"j\"/><geom size=\"0.1\"/><site name=\"s\"/></body>"
                          "<body name=\"c\" pos=\"1 0 0\"><joint name=\"k\"/><geom size=\"0.1\"/></body></worldbody>";
  auto with = [&](const std::string& name, const std::string& actuators) {
    return writeFile(dir, name, arm + "<actuator>" + actuators + "</actuator></mujoco>");
  };
  CHECK(errorOf(with("filter.xml", "<general name=\"slow\" joint=\"j\" dyntype=\"filter\" dynprm=\"0.1\"/>"))
            .find("actuator 'slow' has activation dynamics (dyntype integrator, filter, muscle or user); dynlab reads motor, position, "
                  "velocity and general actuators on a hinge or slide joint") != std::string::npos);
  CHECK(errorOf(with("site.xml", "<general name=\"crank\" site=\"s\" gear=\"1 0 0 0 0 0\"/>")).find("actuator 'crank' drives a site, a body or a slider-crank") !=
        std::string::npos);
  CHECK(errorOf(with("huge.xml", "<motor name=\"m\" joint=\"j\" gear=\"1e300\"/>")).find("actuator 'm''s gear is 1e+300") != std::string::npos);
  // Two spheres that may touch: one note naming them; --ignore-contacts: none.
  const fs::path plain = with("plain.xml", "<motor name=\"m\" joint=\"j\"/>");
  const model_file::LoadedModel m = model_file::load(plain.string());
  REQUIRE(m.notes.size() == 1);
  CHECK(m.notes[0] == "2 geoms collide in MuJoCo but not here (e.g. 'geom #0' and 'geom #1'): dynlab has no geom–geom contact; the hand engine, "
                      "Bullet and MuJoCo's cross-check all run without it");
  model_file::LoadOptions quiet;
  quiet.ignore_contacts = true;
  CHECK(model_file::load(plain.string(), quiet).notes.empty());
  // A <contact><pair> between geoms that filter each other out: noted, not refused.
  const std::string paired = "<mujoco><default><geom size=\"0.1\" contype=\"0\" conaffinity=\"0\"/></default><worldbody>"
                             "<body><joint/><geom name=\"a\"/></body><body pos=\"1 0 0\"><joint/><geom name=\"c\"/></body></worldbody>"
                             "<contact><pair name=\"touch\" geom1=\"a\" geom2=\"c\"/></contact></mujoco>";
  const auto pair_notes = model_file::load(writeFile(dir, "pair.xml", paired).string()).notes;
  REQUIRE(pair_notes.size() == 1);
  CHECK(pair_notes[0].find("1 <contact><pair> (e.g. 'touch') collide in MuJoCo but not here: dynlab has no geom–geom contact") == 0);
}
