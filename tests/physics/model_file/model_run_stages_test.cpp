// The file's actuators and tendons at every RK4 stage whichever hand engine runs the file (labs/generic/
// model_run.cpp: runHand, the sized engine, for a file with loops only; runHandElements, the labs'
// stepping, for one with joint limits or other elements; physics/model_file/actuators.h's
// DrivenMechanism): a servo arm whose shoulder has a range it never reaches runs as the same arm without
// the range, to rounding, and both converge at RK4's fourth order (an actuator held over the step, as
// runHandElements had it, is first order: the errors then halve with dt instead of falling 16-fold).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "labs/generic/model_run.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
using namespace dyn::test_model_file;

namespace {

// Two hinges under gravity, a position servo on the shoulder and a velocity servo on the elbow, a
// tendon spring across both, started from a keyframe away from the servo's target; `range` on the
// shoulder or nothing.
std::string servoArm(const std::string& range) {
  return R"(<mujoco><compiler angle="radian"/><option gravity="0 0 -9.81"/><default><geom contype="0" conaffinity="0"/><joint axis="0 1 0"/></default>
    <worldbody><body name="upper"><joint name="shoulder" )" + range + R"(/><geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03" mass="1"/>
      <body name="fore" pos="0.4 0 0"><joint name="elbow"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.03" mass="0.5"/></body></body></worldbody>
    <tendon><fixed name="bend" stiffness="2" damping="0.1"><joint joint="shoulder" coef="1"/><joint joint="elbow" coef="0.5"/></fixed></tendon>
    <actuator><position name="hold" joint="shoulder" kp="20"/><velocity name="brake" joint="elbow" kv="0.5"/></actuator>
    <keyframe><key name="start" qpos="0.3 -0.2" qvel="0 1" ctrl="-0.4 0.5"/></keyframe></mujoco>)";
}

model_file::LoadedModel loadArm(const std::filesystem::path& dir, const std::string& name, const std::string& range) {
  model_file::LoadOptions o;
  o.key = "start";
  return model_file::load(writeFile(dir, name, servoArm(range)).string(), o);
}

// The run's joint angles at its end (and the largest gap between two runs' angles over their rows).
VecN lastQ(const app::ModelRun& r) {
  const std::size_t last = r.trace.rows() - 1;
  return (VecN(2) << r.trace.at(last, "q_shoulder"), r.trace.at(last, "q_elbow")).finished();
}
double largestGap(const app::ModelRun& a, const app::ModelRun& b) {
  REQUIRE(a.trace.rows() == b.trace.rows());
  double worst = 0;
  for (std::size_t k = 0; k < a.trace.rows(); ++k)
    for (const char* c : {"q_shoulder", "q_elbow", "v_shoulder", "v_elbow"}) worst = std::max(worst, std::abs(a.trace.at(k, c) - b.trace.at(k, c)));
  return worst;
}

app::ModelRun run(const model_file::LoadedModel& m, double dt, double duration) {
  ConstrainedMechanism<Spatial> desc(m.mechanism);
  const VecN tau = VecN::Zero(2);
  return m.contacts.empty() ? app::runHand(m, desc, dt, duration, tau) : app::runHandElements(m, desc, dt, duration, tau);
}

}  // namespace

TEST_CASE("a servo arm with a joint range it never reaches runs as the arm without it, at RK4's fourth order") {
  static const std::filesystem::path dir = scratchFolder("model_run_stages");
  const model_file::LoadedModel free = loadArm(dir, "free.xml", ""), ranged = loadArm(dir, "ranged.xml", R"(range="-3 3" limited="true")");
  REQUIRE(free.contacts.empty());
  REQUIRE(ranged.contacts.size() == 2);  // the shoulder's two stops: runHandElements
  const double dt = 1e-2, duration = 1.0;
  const app::ModelRun a = run(free, dt, duration), b = run(ranged, dt, duration);
  REQUIRE(a.ok);
  REQUIRE(b.ok);
  CHECK(std::abs(lastQ(a)[0] - 0.3) > 0.1);  // the servo moved the shoulder (towards −0.4), not to its stops
  for (std::size_t k = 0; k < b.trace.rows(); ++k) CHECK(std::abs(b.trace.at(k, "q_shoulder")) < 2.5);
  // The same forces at the same stages: only rounding apart over the 100 steps.
  const double gap = largestGap(a, b);
  MESSAGE("max |x_runHand - x_runHandElements| over 1 s at dt 0.01: ", gap);
  CHECK(gap <= 1e-14);
  // Fourth order: against a run at dt/16, halving dt divides the error at the end by about 16.
  const VecN reference = lastQ(run(ranged, dt / 16, duration));
  double previous = 0;
  for (const double h : {dt, dt / 2, dt / 4}) {
    const double error = (lastQ(run(ranged, h, duration)) - reference).cwiseAbs().maxCoeff();
    MESSAGE("dt ", h, ": error at 1 s ", error);
    if (previous > 0) CHECK(previous / error > 12);
    previous = error;
  }
}

TEST_CASE("a joint range that leaves out the reference pose (the Panda's joint4): a keyframe inside it starts the run, one outside is one line") {
  static const std::filesystem::path dir = scratchFolder("model_run_stages_keys");
  auto error = [&](const std::string& name, const std::string& range, const std::string& key) {
    model_file::LoadOptions o;
    o.key = key;
    try {
      model_file::load(writeFile(dir, name, servoArm(range)).string(), o);
    } catch (const model_file::ModelFileError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  // q0 = 0 lies outside [0.2, 3]: refused from q0, naming the way out; the keyframe's 0.3 is inside.
  CHECK(error("outside.xml", R"(range="0.2 3")", "").find("joint 'shoulder' starts at 0, outside its range [0.2, 3] (its ref, or 0); expected the reference pose "
                                                          "inside the range, or a keyframe of the file that does (--key start)") != std::string::npos);
  CHECK(error("outside.xml", R"(range="0.2 3")", "start").empty());
  // No keyframe of the file inside the range: the option named in general.
  CHECK(error("past.xml", R"(range="0.5 3")", "").find("inside the range, or a keyframe that starts inside it (--key NAME)") != std::string::npos);
  // A keyframe past a stop: one line naming the joint.
  CHECK(error("past.xml", R"(range="0.5 3")", "start").find("keyframe 'start': its qpos puts joint 'shoulder' at 0.3, outside its range [0.5, 3]") !=
        std::string::npos);
}
