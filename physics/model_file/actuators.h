// A model file's actuators and fixed tendons in the hand engine (model_file.h's Actuator: MuJoCo's affine
// law on a joint or a fixed tendon; TendonSpring: a fixed tendon's own spring, damper and friction): the
// torques they put on the coordinates at a state, and the hand engine with them evaluated at every stage
// of its step (as MuJoCo's mj_forward evaluates them at each RK4 stage), so a position servo acts as the
// spring it is and a velocity servo as the damper. Bullet gets the same torques at each step's start
// (labs/generic/model_run.cpp), as it gets joint springs. No MuJoCo here: the laws are plain data.
#pragma once
#include <memory>
#include <vector>

#include "physics/constrained_mechanism.h"
#include "physics/integrate.h"
#include "physics/model_file/model_file.h"

namespace dyn::model_file {

// Σ gear · coef_k · force of each actuator on its path's coordinates at (q, v) with controls ctrl (one
// per actuator): MuJoCo's qfrc_actuator.
VecN actuatorTorques(const std::vector<Actuator>& actuators, const VecN& ctrl, const VecN& q, const VecN& v);

// Σ coef_k · f of each fixed tendon's spring, damper and friction at (q, v): MuJoCo's qfrc_passive less
// the joints' own terms (its frictionloss, a constraint in MuJoCo, smoothed here as a joint's is).
VecN tendonTorques(const std::vector<TendonSpring>& tendons, const VecN& q, const VecN& v);

// What the file drives the coordinates with beyond the description: its actuators at its ctrl and its
// fixed tendons' springs, dampers and friction; none: zero.
VecN actuatorTorques(const LoadedModel& m, const VecN& q, const VecN& v);

// Both laws of a model (its actuators at its ctrl, its tendons), kept by the engines that add them.
struct Drive {
  std::vector<Actuator> actuators;
  VecN ctrl;
  std::vector<TendonSpring> tendons;
  explicit Drive(const LoadedModel& m) : actuators(m.actuators), ctrl(m.ctrl), tendons(m.tendons) {}
  bool empty() const { return actuators.empty() && tendons.empty(); }
  VecN torques(const VecN& q, const VecN& v) const;
};

// engine with the model's actuators (at its ctrl) and tendons added to τ at each evaluation, its books
// counting their work with τ's; engine itself when the model has none.
std::unique_ptr<ConstrainedSystem> withActuators(std::unique_ptr<ConstrainedSystem> engine, const LoadedModel& m);

// The description's mechanism (dynamically sized, its contacts closed and opened between steps:
// stepLocatingContacts) with the model's drive evaluated at every stage its integrator evaluates, as
// withActuators does for the sized engine. hold(q, v, τ) at a step's start gives the τ to step with:
// τ plus the drive there, which the step's own contact updates (a touchdown located inside it) see;
// each stage at (q', v') then adds the drive's change since, d(q', v') − d(q, v) (zero at the first).
// Stepped without hold, τ is taken as the plain τ (each stage adds the whole drive).
// Mechanism: the dynamically sized one (DrivenMechanism), or one with the joints fixed (hand_engine.h's
// SizedElements: the PUMA 560's six joints, its limit rows dynamic).
template <class Mechanism = ConstrainedMechanism<Spatial>>
class DrivenMechanismT final : public Mechanism {
 public:
  explicit DrivenMechanismT(const LoadedModel& m) : Mechanism(m.mechanism), drive_(m), held_(VecN::Zero(Eigen::Index(m.joints.size()))) {}
  VecN hold(const VecN& q, const VecN& v, const VecN& tau) {
    if (drive_.empty()) return tau;
    held_ = drive_.torques(q, v);
    return tau + held_;
  }
  bool empty() const { return drive_.empty(); }
  // (Without a drive, τ passes through untouched: a step allocates nothing.)
  void derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a, double& work, double& friction) override {
    if (drive_.empty()) return Mechanism::derivatives(q, v, tau, stab, a, work, friction);
    Mechanism::derivatives(q, v, staged(q, v, tau), stab, a, work, friction);
  }
  void accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a) override {
    if (drive_.empty()) return Mechanism::accelerations(q, v, tau, stab, a);
    Mechanism::accelerations(q, v, staged(q, v, tau), stab, a);
  }

 private:
  VecN staged(const VecN& q, const VecN& v, const VecN& tau) const { return tau + (drive_.torques(q, v) - held_); }
  Drive drive_;
  VecN held_;
};
using DrivenMechanism = DrivenMechanismT<>;

// Servos stiffer than RK4 at step dt can follow: the actuators' stiffness K = Σ −gear² bias[1] c cᵀ and
// damping C = Σ −gear² bias[2] c cᵀ (c: the path's coefficients on the coordinates) on M (at the run's start, armature included) make x = (q, v) move as
// x' = [0 1; −M⁻¹K −M⁻¹C] x, whose modes λ RK4 follows only while |R(λ dt)| ≤ 1 (R(z) = 1 + z + z²/2 +
// z³/6 + z⁴/24). A note naming the step they need (halvings of dt), or "" when RK4 follows them.
// (MuJoCo 3's implicit integrators, which files such as Menagerie's Panda ask for, take these terms
// implicitly; dynlab's RK4 does not.)
std::string stiffServoNote(const LoadedModel& m, const MatN& M, double dt);

// What an actuator drives, for summaries: "joint wrist", or "tendon split (0.5 finger_left + 0.5 finger_right)".
std::string describePath(const LoadedModel& m, const Actuator& a);
// A tendon's own forces: "tendon sync (finger_left − finger_right): stiffness 40 about length 0.01, damping 0.5".
std::string describeTendon(const LoadedModel& m, const TendonSpring& t);

// "2 actuators (servo_a, servo_b) at ctrl (0.5, 0)" for summaries; "" when none.
std::string describeControls(const LoadedModel& m);

}  // namespace dyn::model_file
