// Slider crank (lecture §3): a 3-link planar arm in the vertical plane whose tip holds a slider
// of mass m_c on the x axis. Generalized coordinates q = (θ1, θ2, θ3, x_c), rates v = (θ', v_c).
//   φ(q) = (θ1+θ2+θ3, x_T(θ) − x_c, y_T(θ)) = 0,   J θ' = A v_c,  A = (0, 1, 0)
//   load separate:  m_c x_c'' = A^T f_T = f_Tx      (b_c = G_c = 0, A' = 0)
// solved with the generic eq. (2) (physics/constrained.h) at every evaluation.
// One degree of freedom: the crank angle θ1 is the independent coordinate (regular everywhere
// when l1 < l2; x_c is not, at the dead centres).
#pragma once
#include <array>

#include "physics/chain.h"
#include "physics/constrained_solve.h"
#include "physics/integrate.h"

namespace dyn::slider_crank {

struct Link {
  double length, mass, inertia;  // m, kg, kg·m² about the centre of mass
  Eigen::Vector2d com;           // centre of mass in the link frame (x along the link)
};

struct Params {
  std::array<Link, 3> links;
  double load_mass = 0.5;                 // m_c, kg
  Eigen::Vector2d gravity{0.0, -9.81};    // world, m/s²
};

class Mechanism final : public ConstrainedSystem {
 public:
  // Eq. (2) at the mechanism's fixed sizes: 3 joints, 3 constraint rows, 1 slider coordinate.
  using Problem = ConstrainedProblemT<3, 3, 1>;
  using Solution = ConstrainedSolutionT<3, 3, 1>;

  explicit Mechanism(const Params& params);

  // ConstrainedSystem
  int nq() const override { return 4; }
  void accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a) override;
  void constraint(const VecN& q, VecN& phi, MatN& G) override;
  void metric(const VecN& q, MatN& W) override;
  bool correction(const VecN& q, const VecN& e, VecN& dx) override;
  bool recoverDependent(VecN& q, VecN& v) override;

  // The full solve of eq. (2) at a state: α_c, f_T = (τ_T, f_Tx, f_Ty), θ''.
  Solution solve(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab = nullptr);

  // Consistent initial state from the crank angle on the branch sign(cos(θ1+θ2)) = branch.
  // Returns false if the crank angle cannot be reached (|l1 sin θ1| > l2).
  bool initialState(double theta1, double theta1_rate, int branch, VecN& q, VecN& v) const;

  // Kinematics for controllers and drawing (θ only).
  Eigen::Vector2d tip(const Eigen::Vector3d& theta) const;
  std::array<Eigen::Vector2d, 4> jointPoints(const Eigen::Vector3d& theta) const;  // joints 1..3 and tip
  void tipJacobian(const Eigen::Vector3d& theta, const Eigen::Vector3d& theta_rate, MatN& J, VecN& Jdot_qd);
  Eigen::Vector3d gravityTorque(const Eigen::Vector3d& theta);  // G(θ)

  double energy(const VecN& q, const VecN& v);        // T + U of arm and slider
  double residual(const VecN& q);                     // |φ|∞
  const Params& params() const { return params_; }
  const TreeModel<Planar>& tree() const { return tree_; }

 private:
  // Position stage at θ: transforms, M and the tip J (skipped when θ is the one evaluated last).
  void positionStage(const Eigen::Vector3d& theta);
  // Velocity stage at θ', after the position stage: velocities, h = Cθ' + G and J'θ'.
  void velocityStage(const Eigen::Vector3d& theta_rate);
  // The solve of eq. (2) at a state, without remembering it.
  Solution evaluate(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab);
  Planar::Pos tipPoint() const { return {params_.links[2].length, 0.0}; }  // in link 3's frame
  Params params_;
  TreeModel<Planar> tree_;
  TreeData<Planar> data_;
  Problem problem_;  // M, J from the position stage; h, J'θ' from the velocity stage
  ConstrainedFactorT<3, 3, 1> factor_;  // eq. (2) factored at the position stage's θ
  bool factored_ = false;               // false near singular configurations: the pivoted LU
  Eigen::Vector3d theta_;        // the θ of the position stage held in data_ and problem_
  bool have_position_ = false;
  // The last solve() without stabilisation and its inputs: the trace row's solve, which RK4's
  // first stage then reuses.
  VecN last_q_, last_v_, last_tau_;
  Solution last_;
};

}  // namespace dyn::slider_crank
