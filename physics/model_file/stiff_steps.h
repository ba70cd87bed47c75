// The sub-steps a model file's run takes so that RK4 (and Bullet's Euler) follow its fastest mode. Real
// files carry modes far faster than their motion: in Cassie's leg the foot crank's damper of 1 N·m·s
// acts on a crank and plantar rod of ~1.9e-4 kg·m² (|λ| ≈ 5,300–5,600 1/s), the Achilles rod spins
// about its own axis with 0.01 N·m·s on 3.8e-6 kg·m² (2,660 1/s; the fastest in the whole robot, where
// the crank's loop ties it to the foot). At the file's 0.5 ms the crank's mode sits at RK4's stability
// edge on the real axis (|λ| h = 2.66–2.8 against 2.785): one step multiplies it by R(−2.66) = 0.83
// where it decays by e^−2.66 = 0.07, the books drift 3e-3 J where three sub-steps hold them to 2e-6 J,
// and Bullet's explicit damper (|1 − λh| = 1.7) blows up. MuJoCo's own Euler takes joint
// damping implicitly for this reason. Here the mode is found where it lives — the motion linearised at
// the start state, x = (δq, v), x' = A x by central differences of the engine's accelerations (loops,
// springs, dampers, armature, servos: every term the run integrates) — and the step is cut into equal
// sub-steps h = dt / s with |λ|max h ≤ kStiffStep (RK4 then follows each decaying mode to ~2 %, and
// the books close at RK4's own error; semi-implicit Euler is stable to |λ| h = 2). τ is held over the
// sub-steps as over the step (integrate.h). A file whose fastest mode is slow keeps s = 1: its run is
// bit for bit what it was.
#pragma once
#include <string>

#include "physics/integrate.h"
#include "physics/model_file/model_file.h"

namespace dyn::model_file {

// |λ| h a sub-step may reach (dimensionless).
inline constexpr double kStiffStep = 1.0;
// At most this many sub-steps per step (a mode faster than kStiffStep · kMaxSubsteps / dt is reported,
// and run at this many).
inline constexpr int kMaxSubsteps = 64;

// The fastest mode of the linearised motion at (q, v) with τ held: |λ| (1/s) and the rate coordinate that
// moves most in it (a joint name; "" without any).
struct FastestMode {
  double rate = 0;
  std::string joint;
};
FastestMode fastestMode(ConstrainedSystem& engine, const LoadedModel& m, const VecN& q, const VecN& v, const VecN& tau);
// The model's fastest mode at its start state, controls held (its actuators through withActuators).
FastestMode fastestMode(const LoadedModel& m);

// Sub-steps per step dt: ⌈rate dt / kStiffStep⌉ within [1, kMaxSubsteps].
int stiffSubsteps(double rate, double dt);

// "" when one step follows the fastest mode; else one sentence naming it and the sub-steps taken.
std::string stiffStepNote(const FastestMode& mode, double dt);

}  // namespace dyn::model_file
