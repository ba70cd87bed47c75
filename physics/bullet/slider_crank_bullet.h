// Bullet reference model of the slider crank (lecture §3): a 3-link planar arm in the
// vertical x–y plane (gravity along −y) whose tip holds a slider of mass m_c on the x axis,
// with θ1+θ2+θ3 = 0 and y_T = 0.
// This header is Eigen-only; Bullet stays inside the .cpp (the only place that includes it).
#pragma once
#include <Eigen/Core>
#include <array>
#include <memory>

namespace dyn::bullet {

// One link in its own frame: the joint at the origin, x along the link to the next joint.
struct PlanarLink {
  double length;           // m, joint to next joint (or tip)
  double mass;             // kg
  double inertia;          // kg·m², about the centre of mass, axis z
  Eigen::Vector2d com;     // m, centre of mass in the link frame
};

struct SliderCrankModel {
  std::array<PlanarLink, 3> links;
  double load_mass;             // kg, slider on the x axis
  Eigen::Vector2d gravity;      // m/s², world frame, e.g. (0, −9.81)
  Eigen::Vector3d q0, qd0;      // consistent initial joint angles (relative) and rates
};

// Conventions shared with the hand-written model:
//  * θ1 is link 1's angle from world x; θ2, θ3 are relative angles; joint 1 at the origin;
//  * x_c, v_c: the slider position/velocity on the x axis (= the arm tip);
//  * tip force f_T = (τ_T, f_Tx, f_Ty): the wrench the arm applies to the slider at the tip,
//    world axes (N·m, N, N).
class SliderCrankBullet {
 public:
  SliderCrankBullet(const SliderCrankModel& model, double dt);
  ~SliderCrankBullet();
  SliderCrankBullet(const SliderCrankBullet&) = delete;
  SliderCrankBullet& operator=(const SliderCrankBullet&) = delete;

  // Advance one fixed step of dt with joint torques tau held over the step.
  void step(const Eigen::Vector3d& tau);

  Eigen::Vector3d q() const;    // θ1, θ2, θ3 (rad)
  Eigen::Vector3d qd() const;   // rates (rad/s)
  double x_c() const;           // slider x (m)
  double v_c() const;           // slider x rate (m/s)
  Eigen::Vector3d tipForce() const;  // f_T of the last step, as above
  double time() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyn::bullet
