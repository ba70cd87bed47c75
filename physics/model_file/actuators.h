// A model file's actuators in the hand engine (model_file.h's Actuator: MuJoCo's affine law on a joint):
// the torques they put on the coordinates at a state, and the hand engine with them evaluated at every
// stage of its step (as MuJoCo's mj_forward evaluates them at each RK4 stage), so a position servo acts
// as the spring it is and a velocity servo as the damper. Bullet gets the same torques at each step's
// start (labs/generic/model_run.cpp), as it gets joint springs. No MuJoCo here: the law is plain data.
#pragma once
#include <memory>
#include <vector>

#include "physics/integrate.h"
#include "physics/model_file/model_file.h"

namespace dyn::model_file {

// Σ gear · force of each actuator on its coordinate at (q, v) with controls ctrl (one per actuator).
VecN actuatorTorques(const std::vector<Actuator>& actuators, const VecN& ctrl, const VecN& q, const VecN& v);

// The model's actuators at its ctrl as a torque law; none: zero.
inline VecN actuatorTorques(const LoadedModel& m, const VecN& q, const VecN& v) { return actuatorTorques(m.actuators, m.ctrl, q, v); }

// engine with the model's actuators (at its ctrl) added to τ at each evaluation, its books counting
// their work with τ's; engine itself when the model has none.
std::unique_ptr<ConstrainedSystem> withActuators(std::unique_ptr<ConstrainedSystem> engine, const LoadedModel& m);

// Servos stiffer than RK4 at step dt can follow: the actuators' stiffness K = diag(−gear² bias[1]) and
// damping C = diag(−gear² bias[2]) on M (at the run's start, armature included) make x = (q, v) move as
// x' = [0 1; −M⁻¹K −M⁻¹C] x, whose modes λ RK4 follows only while |R(λ dt)| ≤ 1 (R(z) = 1 + z + z²/2 +
// z³/6 + z⁴/24). A note naming the step they need (halvings of dt), or "" when RK4 follows them.
// (MuJoCo 3's implicit integrators, which files such as Menagerie's Panda ask for, take these terms
// implicitly; dynlab's RK4 does not.)
std::string stiffServoNote(const LoadedModel& m, const MatN& M, double dt);

// "2 actuators (servo_a, servo_b) at ctrl (0.5, 0)" for summaries; "" when none.
std::string describeControls(const LoadedModel& m);

}  // namespace dyn::model_file
