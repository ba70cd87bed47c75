// The rolling-unicycle lab (lecture §3 "Unicycle"): a disk wheel under the rolling constraint (no slip,
// no tilt: mechanism.h), whose reduced dynamics decouple into one loop per torque
//   (I_a + m r²) θ'' = τ_y,   I_z φ'' = τ_z      (controller.h: PI on the spin rate, PD on the heading)
// following the path from unicycle.json.
#pragma once
#include "labs/settings_lab.h"
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

class UnicycleLab final : public SettingsLab<Settings> {
 public:
  // Its tables (settings_lab.h): the trace columns and their units, the agreement's units, the passive check.
  explicit UnicycleLab(Settings s);
  // The run: the wheel rolling from its start pose, the path follower; Bullet also drives its
  // friction-contact wheel, which can skid (lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // The mechanism written for MuJoCo (mujoco.xml beside the JSON) and the lab's start (lab.cpp).
  MujocoTwin mujocoTwin() const override;
  const Path& path() const { return path_; }
  // The grade: cross-track, speed, skid margin, energy and residual (lab.cpp); the loops screened (linearise.cpp).
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  std::vector<LinearLoop> linearise() const override;
  // The picture: the wheel, its path, the contact force (draw.cpp).
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;

 private:
  Path path_;
};

}  // namespace dyn::unicycle
