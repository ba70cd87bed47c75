// The slider-crank lab: mechanism + controller + scenario from slider_crank.json.
#pragma once
#include "labs/lab.h"
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

class SliderCrankLab final : public Lab {
 public:
  explicit SliderCrankLab(Settings s);
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

}  // namespace dyn::slider_crank
