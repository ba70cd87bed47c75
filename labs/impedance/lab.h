// The impedance-control lab (lecture §4): the motion-control lab's 3-link arm (reused from
// labs/motion_control/mechanism.h) asked to make its hand feel like a given mass-spring-damper (the
// exercise's target, impedance.json "target"; the controller's own K, D, M are the student's gains)
//   M_des ẍ + D_des ẋ + K_des (x − x_ref) = F_ext,   x = (x_tip, y_tip, φ_tip), per axis (diagonal),
// realised three ways (controller kind): joint_space, task_space, feedback_linearisation; plus none
// and constant. The environment: a tip force (step or push) and/or a wall (a planar PlaneContact).
#pragma once
#include <Eigen/Core>

#include "labs/motion_control/controller.h"
#include "labs/motion_control/mechanism.h"
#include "labs/settings_lab.h"
#include "physics/forces.h"

namespace dyn::impedance {

// The hand engine's arm with the wall's contact row (fixed sizes; instantiated in mechanism.cpp).
using WallArm = ConstrainedMechanism<Planar, 3, 1, 0>;

enum class Kind { None, Constant, JointSpace, TaskSpace, FeedbackLinearisation };

struct Target {
  Eigen::Vector3d M, D, K;  // per task axis (x, y, φ): kg or kg·m², N·s/m or N·m·s/rad, N/m or N·m/rad
};

// F_ext(t) at the tip: zero before start, ramps to value over rise, held for hold (0: for ever), then off.
struct Force {
  Eigen::Vector2d value = Eigen::Vector2d::Zero();
  double start = 0.2, rise = 0, hold = 0;
  Eigen::Vector2d at(double t) const;
  ForceProfile profile() const { return {start, rise, hold}; }
};

struct Wall {
  bool enabled = false;
  double x = 1.0;           // m, the wall is the plane x = x_wall (the arm on its left)
  double stiffness = 0;     // N/m, 0 rigid
  double damping = 0;       // N·s/m (compliant)
  double radius = 0.01;     // m, the tip's ball
};

struct Settings {
  motion_control::Params plant, model;  // the arm, and as the controller believes it (rigid, frictionless)
  Eigen::Vector3d pose;                 // rad, the initial joint angles: x_ref is the tip pose there
  Eigen::Vector3d tau_max, constant;    // N·m
  Kind kind = Kind::TaskSpace;
  // The exercise's target (impedance.json's "target": graded, drawn, x_target) and the impedance the
  // controller is programmed with (the student's gains k, d, m): the rubric grades the hand against
  // the target, whatever the gains, so no realisation can dodge it by choosing its own target.
  Target target, law;
  // joint_space's inner loop: the motion-control lab's joint controller (pid, computed_torque or
  // pd_gravity with its gains, labs/motion_control/controller.h) tracking θ_des from inverse kinematics.
  motion_control::ControllerConfig inner;
  double period = 0.001;                // s, control period
  double noise = 0, delay = 0;          // force sensor: Gaussian σ (N), delay (s)
  Force force;
  Wall wall;
  StepOptions step;
  double duration = 1;
};

Settings parseSettings(const JsonView& config);
// The unit step response of ẍ + 2ζω ẋ + ω² x = ω² from rest (the target's push response / static).
double unitStep(double omega, double zeta, double t);
// Task coordinates (x, y, φ) of the tip at joint angles θ.
Eigen::Vector3d tipPose(const motion_control::Params& p, const Eigen::Vector3d& theta);
// Joint angles of tip pose x (planar 3R, elbow on the side of `like`); false if out of reach.
bool inverseKinematics(const motion_control::Params& p, const Eigen::Vector3d& x, const Eigen::Vector3d& like,
                       Eigen::Vector3d& theta);

class ImpedanceLab final : public SettingsLab<Settings> {
 public:
  // Its tables (settings_lab.h): the trace columns and their units, the agreement's units, the passive check.
  explicit ImpedanceLab(Settings s);
  // The run: the arm at its pose, the impedance law of the kind chosen, the push and the wall (lab.cpp).
  std::unique_ptr<Simulation> simulate(Engine engine) const override;
  // The mechanism written for MuJoCo (mujoco.xml beside the JSON) and the lab's start (lab.cpp).
  MujocoTwin mujocoTwin() const override;
  // The grade: the hand against the target's response, the wall's force (metrics.cpp); the loops
  // screened (linearise.cpp).
  json metrics(const Trace& trace) const override;
  json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const override;
  std::vector<LinearLoop> linearise() const override;
  // The picture: the arm, the wall, the spring glyph (draw.cpp): along the push (x̂ without one), its
  // stretch magnified g times.
  void scene(const Trace& trace, std::size_t row, const Trace* ghost, Scene& out) const override;
  void overlay(const Trace& trace, std::size_t row, Overlay& out) const override;
  Eigen::Vector2d pushDirection() const;
  double springMagnification(const Trace& tr) const;
};

}  // namespace dyn::impedance
