// The multi-finger grasp lab: mechanism + controller + scenario from grasp.json.
#pragma once
#include "labs/grasp/controller.h"
#include "labs/lab.h"

namespace dyn::grasp {

// A push on the object (world axes, at its centre of mass) from `start` for `duration` s.
struct Disturbance {
  Eigen::Vector2d force = Eigen::Vector2d::Zero();  // N
  double start = 0, duration = 0;                   // s
  bool active(double t) const { return force != Eigen::Vector2d::Zero() && t >= start && t < start + duration; }
};

struct Settings {
  Params params;                                    // the plant
  Params model;                                     // what the controller believes: the plant's fingers, its own object and μ̂
  Eigen::Vector3d pose0 = Eigen::Vector3d::Zero();  // initial object pose (ψ, x, y)
  StepOptions step;
  double duration = 1;
  ControllerConfig controller;
  Reference reference;
  Disturbance push;
  double settle_time = 0.5;   // s, internal-force metrics start here
  double arrow_scale = 0.01;  // m per N, drawing only
};

// Reads and validates the lab JSON; throws InputError naming file and path.
Settings parseSettings(const JsonView& config);

class GraspLab final : public Lab {
 public:
  explicit GraspLab(Settings s);
  std::vector<std::string> columns() const override { return columns_; }
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
  int fingers() const { return int(s_.params.fingers.size()); }

 private:
  Settings s_;
  std::vector<std::string> columns_;
};

}  // namespace dyn::grasp
