// The hand engine's RK4 run of a loaded model against MuJoCo's own RK4 run (mj_step with RK4) at the
// same step from the model's start, its controls held: the same equations at the same order evaluated
// at the same stages, so only rounding apart when the laws agree (the actuator and tendon tests).
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <string>

#include "physics/integrate.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/model_file.h"

namespace dyn::test_model_file {

// The largest |q_hand − q_mujoco|∞ over `steps` RK4 steps of dt from the model's start; the hand
// engine with the file's actuators and tendons (or without: actuated false).
inline double rk4Difference(const model_file::LoadedModel& m, double dt, int steps, bool actuated = true) {
  model_file::MujocoSimulation mj(m, dt, true);
  REQUIRE(mj.describe().find("RK4") != std::string::npos);
  mj.reset(m.start_q, m.start_v);
  auto engine = model_file::handEngine(m.mechanism);
  if (actuated) engine = model_file::withActuators(std::move(engine), m);
  StepOptions o;
  o.dt = dt;
  VecN q = m.start_q, v = m.start_v, qm, vm;
  const VecN zero = VecN::Zero(q.size());
  double worst = 0;
  for (int k = 0; k < steps; ++k) {
    REQUIRE(mj.step());
    REQUIRE(step(*engine, o, zero, q, v));
    mj.state(qm, vm);
    worst = std::max(worst, (q - qm).cwiseAbs().maxCoeff());
  }
  return worst;
}

}  // namespace dyn::test_model_file
