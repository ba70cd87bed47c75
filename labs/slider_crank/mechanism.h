// Slider crank (lecture §3) described as data: a 3-link planar arm in the vertical plane (a tree of
// three revolute joints) whose tip is welded to a slider of mass m_c, a payload free along world x:
//   q = (θ1, θ2, θ3, x_c),  φ(q) = (θ1+θ2+θ3, x_T(θ) − x_c, y_T(θ)) = 0  (a point closure, all rows)
//   J θ' = A v_c,  A = (0, 1, 0);   load separate: m_c x_c'' = Aᵀ f_T = f_Tx
// physics/ does the rest (the generic mechanism, eq. (2), both engines). What is particular stays here:
// the inverse kinematics from the crank angle θ1 (the independent coordinate, regular everywhere when
// l1 < l2; x_c is not, at the dead centres), its branch, and the closed-form joint points for drawing.
// For Bullet, the loop is cut at joint 1 (20× more accurate than welding the tip; notes/bullet-reference.md).
// A tool at the tip (tool_mass) is part of link 3: its weight hangs on the arm, straight above the rail.
#pragma once
#include <array>

#include "physics/constrained_mechanism.h"

namespace dyn::slider_crank {

struct Link {
  double length, mass, inertia;  // m, kg, kg·m² about the centre of mass
  Eigen::Vector2d com;           // centre of mass in the link frame (x along the link)
};

struct Params {
  std::array<Link, 3> links;
  double load_mass = 0.5;                 // m_c, kg
  double tool_mass = 0.0;                 // kg, a point mass at link 3's tip: the arm's tool, part of link 3
  Eigen::Vector2d gravity{0.0, -9.81};    // world, m/s²
};

// The description both engines are built from.
MechanismModel<Planar> describe(const Params& params);

// Eq. (2) at the mechanism's fixed sizes: 3 joints, 3 constraint rows, 1 slider coordinate.
class Mechanism final : public ConstrainedMechanism<Planar, 3, 3, 1> {
 public:
  explicit Mechanism(const Params& params);

  // Independent coordinates: rebuild θ2, θ3, x_c and their rates from θ1 on the current branch.
  bool recoverDependent(VecN& q, VecN& v) override;
  // Consistent initial state from the crank angle on the branch sign(cos(θ1+θ2)) = branch.
  // Returns false if the crank angle cannot be reached (|l1 sin θ1| > l2).
  bool initialState(double theta1, double theta1_rate, int branch, VecN& q, VecN& v) const;

  // Kinematics for controllers and drawing (θ only).
  Eigen::Vector2d tip(const Eigen::Vector3d& theta) const;
  std::array<Eigen::Vector2d, 4> jointPoints(const Eigen::Vector3d& theta) const;  // joints 1..3 and tip
  void tipJacobian(const Eigen::Vector3d& theta, const Eigen::Vector3d& theta_rate, MatN& J, VecN& Jdot_qd);
  Eigen::Vector3d gravityTorque(const Eigen::Vector3d& theta);  // G(θ)
  const Params& params() const { return params_; }

 private:
  Planar::Pos tipPoint() const { return {params_.links[2].length, 0.0}; }  // in link 3's frame
  Params params_;
};

}  // namespace dyn::slider_crank
