// The motion-control lab (lecture §1, §4): an n-link planar arm, rigid or with flexible joints
// (mechanism.h), M(θ)θ'' + C(θ, θ')θ' + G(θ) + friction = τ, moved from pose to pose by PID, computed
// torque or PD + gravity (controller.h), e.g. τ = M̂(θ)(θ_d'' − K_p e − K_d e') + Ĉθ' + Ĝ; the scenario
// from motion_control.json. Angle conventions: trace columns q*, qd*, e* are link-side relative joint
// angles (flexible: θ = θm + δ; the controller itself sees the motor side θm), defl* the deflections δ.
#pragma once
#include "labs/motion_control/controller.h"
#include "labs/settings_lab.h"

namespace dyn::motion_control {

struct Settings {
  Params plant, model;          // the arm as it is, and as the controller believes it
  Trajectory trajectory;
  ControllerConfig controller;
  StepOptions step;
  double duration = 1;
};

// Reads and validates the lab JSON; throws InputError naming file and path.
Settings parseSettings(const JsonView& config);
// The static deflection of a flexible arm held at link angles θ by its motors: k_i δ_i = −G_spring,i.
Eigen::VectorXd staticDeflection(const Params& plant, const Eigen::VectorXd& theta);
// The fastest small-oscillation mode of a flexible arm at link angles θ (rad/s): √ of the largest
// eigenvalue of M⁻¹K (K the springs on the deflections, motors free); 0 for a rigid arm.
double fastestMode(const Params& plant, const Eigen::VectorXd& theta);
// ω dt of the fastest mode that the hand engine's sub-steps keep (RK4's phase error per step ~ (ω dt)⁴/120).
inline constexpr double kResolvedOmegaDt = 0.04;

class MotionControlLab final : public SettingsLab<Settings> {
 public:
  // Its tables (settings_lab.h): the trace columns and their units, the agreement's units, the passive check.
  explicit MotionControlLab(Settings s);
  // The joints' columns (q*, qd*, e*, defl*, tau*, u_i*) by rule, the others from the table.
  std::string unit(const std::string& column) const override;
  // The run: the arm (rigid or flexible) from the trajectory's start, its joint controller (lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // The mechanism written for MuJoCo (mujoco.xml beside the JSON) and the lab's start (lab.cpp).
  MujocoTwin mujocoTwin() const override;
  // The grade: the joint errors over the move and the hold, torques, energy (lab.cpp); each joint's
  // loop at both poses, screened (linearise.cpp).
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  std::vector<LinearLoop> linearise() const override;
  // The picture: the arm and its target pose (draw.cpp).
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;
};

}  // namespace dyn::motion_control
