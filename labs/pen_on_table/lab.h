// The pen-on-table lab (lecture §3 "Pen on table"): a spatial 3-DOF arm whose pen tip touches a table
// under a unilateral contact, gap ≥ 0 and η ≥ 0 (mechanism.h), drawing a circle while pressing f_zd
// by position accommodation (controller.h): an inner task-space position loop, an outer force law on z_des
//   damper  ż_des = −(f_meas − f_zd) / D_z,   spring  z_des = z_ref − (f_meas − f_zd) / K_z
// with the scenario from pen_on_table.json.
#pragma once
#include "labs/pen_on_table/controller.h"
#include "labs/settings_lab.h"

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

class PenOnTableLab final : public SettingsLab<Settings> {
 public:
  // Its tables (settings_lab.h): the trace columns and their units, the agreement's units, the passive check.
  explicit PenOnTableLab(Settings s);
  // The run: the tip start_height above the circle's first point, the accommodation controller (lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // The mechanism written for MuJoCo (mujoco.xml beside the JSON) and the lab's start (lab.cpp).
  MujocoTwin mujocoTwin() const override;
  // The initial state: at rest (or at rates0), the tip start_height above the circle's first point.
  void initialState(VecN& q, VecN& v) const;
  // The grade: the force's overshoot and RMS from touchdown, the circle's error, lift-offs (lab.cpp);
  // the loops screened (linearise.cpp).
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  std::vector<LinearLoop> linearise() const override;
  // When the circle runs at full speed (t_s + T_r).
  double drawingStart() const { return s_.circle.start + std::max(s_.circle.ramp, 0.0); }
  // The picture: the arm, the table, the pen's force (draw.cpp).
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;
};

}  // namespace dyn::pen_on_table
