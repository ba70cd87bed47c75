// The Bullet 3.24 reference model of any mechanism description (physics/mechanism.h), built by one
// builder: trees as one btMultiBody grown from the world (tree joints listed in BulletHints::cut_joints
// become Bullet constraints instead, and constraints that weld two bodies become fixed tree joints
// where that joins the tree), payloads on their guides, every other constraint as its Bullet
// counterpart. It reads back the description's own coordinates (θ, x_c), (θ', v_c) and the force of
// every constraint in the description's convention (body a on body b, world axes, at its point).
// This header is Eigen-only; Bullet stays inside physics/bullet/*.cpp.
#pragma once
#include <memory>
#include <string>

#include "physics/integrate.h"
#include "physics/mechanism.h"

namespace dyn::bullet {

template <class S>
class BulletMechanism {
 public:
  // Planar mechanisms move in Bullet's x–y plane (revolute axes z). Spatial ones (spatial_mechanism.cpp):
  // trees hung from the world, revolute/prismatic joints, rolling constraints modelled as
  // BulletHints::rolling says. Both model plane_contact as a ball on a static plane (contact_balls.h).
  // q0, v0: a consistent state.
  // Throws std::invalid_argument for a description it cannot model (the message says what).
  BulletMechanism(const MechanismModel<S>& model, double dt, const VecN& q0, const VecN& v0);
  ~BulletMechanism();
  BulletMechanism(const BulletMechanism&) = delete;
  BulletMechanism& operator=(const BulletMechanism&) = delete;

  // One fixed step of dt from time t with the tree-joint torques τ held (joint springs and friction of
  // the description are added as joint torques from the state at the start of the step, the external
  // forces as link forces and torques evaluated there at t: Bullet's one step is its one substep). τ may
  // carry n + k values: then the last k are generalised forces on the payloads' free coordinates (ψ, x,
  // y: a torque and a world-axes force at the centre of mass), as for ConstrainedMechanism::solve.
  void step(const VecN& tau, double t = 0);
  // The books (integrate.h) of Bullet's run: each step's held forces times the displacement it took
  // (τ·Δq, F·Δp + τ_F Δφ for an external force, −(b θ' + F_c tanh(θ'/w))·Δθ for friction): first order,
  // as Bullet's own step.
  Books books() const;
  // The state in the description's coordinates.
  void state(VecN& q, VecN& v) const;
  // The force of constraint i over the last step (body a on body b, world axes at its point). Rolling:
  // the ground's force on the wheel, a pure force at the contact of the step (moment ~0). plane_contact:
  // the plane's force on the ball (η n, plus friction when μ > 0) at c − ρ n of the step's start.
  typename S::Vec constraintForce(int i) const;
  // One line for summaries and the bench: how the model was built ("btMultiBody cut at joint 1, ...").
  std::string describe() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyn::bullet
