// The slider-crank lab (lecture §3, closed-chain force control): the arm's tip welded to a slider on a
// rail (mechanism.h), φ(q) = (θ1+θ2+θ3, x_T − x_c, y_T) = 0, driven by direct force control
//   τ = G(θ) + Jᵀ A u + Jᵀ (0, 0, ξ),   u on x_c − x_d,   ξ on the measured rail force f_Ty (controller.h)
// with the scenario from slider_crank.json.
#pragma once
#include "labs/settings_lab.h"
#include "labs/slider_crank/controller.h"

namespace dyn::slider_crank {

struct Settings {
  Params params;
  double theta1 = 0, theta1_rate = 0;
  int branch = 1;  // sign of cos(θ1+θ2)
  StepOptions step;
  double duration = 1;
  ControllerConfig controller;
  Reference reference;
  double settle_time = 0.5;   // s, force metrics start here
  double arrow_scale = 0.02;  // m per N, drawing only
};

// The arm the controller knows: the plant without its tool (mechanism/tool_mass is unmodelled).
Params controllerModel(const Params& plant);

// Reads and validates the lab JSON; throws InputError naming file and path.
Settings parseSettings(const JsonView& config);

class SliderCrankLab final : public SettingsLab<Settings> {
 public:
  // Its tables (settings_lab.h): the trace columns and their units, the agreement's units, the passive check.
  explicit SliderCrankLab(Settings s);
  // The run: the arm and slider assembled at θ1 on their branch, the force controller (lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // The mechanism written for MuJoCo (mujoco.xml beside the JSON) and the lab's start (lab.cpp).
  MujocoTwin mujocoTwin() const override;
  // The grade: x and f_Ty tracking, energy and residual (lab.cpp); the loops screened (linearise.cpp).
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  std::vector<LinearLoop> linearise() const override;
  // The picture: the arm, the rail, the rail force's arrow (draw.cpp).
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;
};

}  // namespace dyn::slider_crank
