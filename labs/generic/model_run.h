// One engine's run of a loaded model (physics/model_file) from its pose at rest with constant joint
// torques, as `dynlab model` writes it and a model file's lab (model_lab.h) replays it: the hand engine
// (RK4 + projection; with dynlab's elements beside the file, stepped as the labs step: contacts closed
// and opened, touchdowns located, their losses in the books) or Bullet, each row's state, energy, work,
// constraint residual and forces (the columns of modelColumns). Shared by dynlab and dynlab-ui.
#pragma once
#include <string>

#include "labs/trace.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/model_file.h"

namespace dyn::app {

// One engine's run: the trace and what the summary reports.
struct ModelRun {
  Trace trace;
  double e0 = 0, residual = 0, balance = 0, kinetic = 0;  // E0, max |φ|∞ (every closure row), max |E − E0 − W|, max kinetic energy
  double position_residual = 0;  // max |φ|∞ of the positions alone (residual less the velocity rows: a coupling's rate, a wheel's slip)
  bool ok = true;
  std::string summary;
  std::string stopped;  // why the run stopped early, when it says (a loop closure that opened)
};

// The trace's columns: t, q_JOINT, v_JOINT, energy, work, constraint_residual, f_CLOSURE_ROW, then
// with a rigid contact `impacts`, then each wheel's f_NAME_long|lat|normal, skid_margin_NAME,
// slip_NAME and each contact's f_NAME_normal|tangent, gap_NAME (an empty trace).
// The trace columns of q, one per entry: q_NAME per hinge or slide, q_NAME_qw … q_NAME_qz per ball's quaternion.
std::vector<std::string> coordinateColumns(const model_file::LoadedModel& m);
Trace modelColumns(const model_file::LoadedModel& m);

// A rigid plane contact among the model's elements: its touchdowns are plastic impacts.
bool anyImpacts(const model_file::LoadedModel& m);

// |φ|∞ a run of the model reports at a state (all): the rows the description holds (the closures' kept
// rows; with dynlab's elements, elementResidual) and every closure row, the dropped ones too
// (closure_rows.h); and the same at the positions alone (positions: the rows' φ, contacts' and joint
// stops' depths, every closure row; no velocity form J v, such as a coupling's rate or a wheel's slip).
struct RunResidual {
  double all = 0, positions = 0;
};
RunResidual runResidual(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, model_file::EveryClosureRow& every, const VecN& q,
                        const VecN& v);
// Whether a run's residual is mostly its rows' velocity form (over twice the positions' share, above
// round-off): then the reports say the positions' share beside it (Bullet's gear row on the 2F-85).
inline bool ratesDominate(double all, double positions) { return all > 2 * positions && all > 1e-12; }

// The power the joints' damping and friction take out of the mechanism (≥ 0), by the description's law.
double frictionPower(const MechanismModel<Spatial>& d, const VecN& v);

// |φ|∞ of a model with dynlab's elements at a state: the closures' and wheels' rows, position and
// velocity forms (a wheel's x, y rows have only the latter: its slip), and each contact's depth past
// its plane. desc: the model's description as a mechanism (its contacts open: gaps read, not held).
double elementResidual(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, const VecN& q, const VecN& v);

// What a run of the model at step dt should say once, beside its numbers: the loader's notes (geoms that
// collide in MuJoCo but not here, limits read and not held, tendon friction, ...), what is drawn other
// than as written, and servos stiffer than RK4 follows at dt (actuators.h's stiffServoNote).
std::vector<std::string> modelNotes(const model_file::LoadedModel& m, double dt);

// The runs, `duration` s at fixed step dt, τ held (n joint torques). mech/desc: the model's
// description as a mechanism (energy, residual and the rows' solves). runHand steps loops only (the
// sized engine, hand_engine.h); runHandElements a model with wheels or contacts; runBullet either.
ModelRun runHand(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, double dt, double duration, const VecN& tau);
ModelRun runHandElements(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, double dt, double duration, const VecN& tau);
ModelRun runBullet(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, double dt, double duration, const VecN& tau);

}  // namespace dyn::app
