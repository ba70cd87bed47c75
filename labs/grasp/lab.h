// The multi-finger grasp lab (lecture §3 "Multi-finger grasp"): two-link fingers hold an object through
// point contacts with friction (mechanism.h), M_c α_c + G_c = Σ_i A_iᵀ f_i, each f_i inside its cone;
// the object-level controller (controller.h) asks a wrench W of the contacts, F = G⁺ W + s d, squeezing
// along the internal forces N(Aᵀ) just enough; the scenario from grasp.json.
#pragma once
#include "labs/grasp/controller.h"
#include "labs/settings_lab.h"

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

class GraspLab final : public SettingsLab<Settings> {
 public:
  // Its tables (settings_lab.h): the trace columns and their units, the agreement's units, the passive check.
  explicit GraspLab(Settings s);
  // The fingers' columns (q*, tau*, f*) by rule, the others from the table.
  std::string unit(const std::string& column) const override;
  // The run: fingers and object assembled at pose0, the object-level controller, the push (lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // The mechanism written for MuJoCo (mujoco.xml beside the JSON) and the lab's start (lab.cpp).
  MujocoTwin mujocoTwin() const override;
  int fingers() const { return int(s_.params.fingers.size()); }
  // The grade: the object's tracking, the internal force, the friction cones' margin (lab.cpp);
  // the loops screened (linearise.cpp).
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  std::vector<LinearLoop> linearise() const override;
  // The picture: fingers, object, friction cones and contact forces (draw.cpp).
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;
};

}  // namespace dyn::grasp
