// The motion-control lab: the arm (mechanism.h), its controller (controller.h) and the scenario from
// motion_control.json. Angle conventions: trace columns q*, qd*, e* are link-side relative joint
// angles (flexible: θ = θm + δ; the controller itself sees the motor side θm), defl* the deflections δ.
#pragma once
#include "labs/lab.h"
#include "labs/motion_control/controller.h"

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
inline constexpr double kResolvedOmegaDt = 0.05;

class MotionControlLab final : public Lab {
 public:
  explicit MotionControlLab(Settings s);
  std::vector<std::string> columns() const override;
  std::string unit(const std::string& column) const override;
  double dt() const override { return s_.step.dt; }
  double duration() const override { return s_.duration; }
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  json metrics(const Trace& trace) const override;
  json agreement(const Trace& hand, const Trace& bullet) const override;
  std::string agreementUnit(const std::string& key) const override;
  std::string referenceEngine() const override;
  PassiveEnergy passiveEnergy() const override;
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;
  std::vector<LinearLoop> linearise() const override;
  const Settings& settings() const { return s_; }

 private:
  Settings s_;
};

}  // namespace dyn::motion_control
