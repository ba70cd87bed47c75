// The pen-on-table lab: the arm, the table and the accommodation controller from pen_on_table.json.
#pragma once
#include "labs/lab.h"
#include "labs/pen_on_table/controller.h"

namespace dyn::pen_on_table {

struct Settings {
  Params params;
  Circle circle;
  double start_height = 0.01;                  // m: the tip above the table at the circle's first point
  Eigen::Vector3d rates0 = Eigen::Vector3d::Zero();  // rad/s, θ' at t = 0
  StepOptions step;
  double duration = 6;
  ControllerConfig controller;
  double overshoot_window = 0.5;  // s after touchdown: the window of the overshoot metric
  int max_liftoffs = 4;           // the run stops at this many lift-offs after the first touchdown (it bounces)
  double arrow_scale = 0.01;      // m per N, drawing only
};

// Reads and validates the lab JSON; throws InputError naming file and path.
Settings parseSettings(const JsonView& config);

class PenOnTableLab final : public Lab {
 public:
  explicit PenOnTableLab(Settings s);
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
  // The initial state: at rest (or at rates0), the tip start_height above the circle's first point.
  void initialState(VecN& q, VecN& v) const;
  // When the circle runs at full speed (t_s + T_r).
  double drawingStart() const { return s_.circle.start + std::max(s_.circle.ramp, 0.0); }

 private:
  Settings s_;
};

}  // namespace dyn::pen_on_table
