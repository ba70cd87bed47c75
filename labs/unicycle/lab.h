// The rolling-unicycle lab: mechanism + controller + path from unicycle.json.
#pragma once
#include "labs/lab.h"
#include "labs/unicycle/controller.h"

namespace dyn::unicycle {

struct Settings {
  Params params;
  double x0 = 0, y0 = 0, phi0 = 0, phi_rate0 = 0, theta_rate0 = 0;  // initial pose and rates
  StepOptions step;
  double duration = 12;
  ControllerConfig controller;
  ReferenceSettings reference;
  double arrow_scale = 0.02;  // m per N, drawing only
};

// Reads and validates the lab JSON; throws InputError naming file and path.
Settings parseSettings(const JsonView& config);

class UnicycleLab final : public Lab {
 public:
  explicit UnicycleLab(Settings s);
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
  const Path& path() const { return path_; }

 private:
  Settings s_;
  Path path_;
};

}  // namespace dyn::unicycle
