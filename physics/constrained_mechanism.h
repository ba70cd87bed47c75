// The generic constrained mechanism: any MechanismModel (mechanism.h) through the one solve of
// eqs. (2)/(3) (constrained_solve.h), as a ConstrainedSystem for the integrators (integrate.h).
//   position stage (θ, x_c):  tree transforms, M (CRBA), every constraint's φ, J, A; M_c; factor (2)
//   velocity stage (θ', v_c): tree velocities, h = Cθ' + G + K(θ − θ_r) + B θ' + F_c tanh(θ'/w) (RNEA),
//                             every constraint's bias J'θ' − A'v_c, payload b_c + G_c, the external
//                             forces at the clock's time (h −= J_Pᵀ F, payloads' share likewise) and
//                             the power of those forces and of friction (the books: integrate.h)
//   solve:                    α_c, η (the constraint forces) and θ'' together
// Both stages are cached: the projection, the trace row and the next step's first RK4 stage revisit
// the same configuration, and the trace row's solve is the first stage's.
// Sizes: Nj tree joints, Nr constraint rows, Nl payload coordinates: Dynamic (bounded by kMaxDof,
// never on the heap in a step) or fixed where a lab knows them (every loop unrolled).
#pragma once
#include <string>
#include <vector>

#include "physics/chain_planar_in_space.h"
#include "physics/constrained_solve.h"
#include "physics/integrate.h"
#include "physics/mechanism.h"

namespace dyn {

template <class S, int Nj = Eigen::Dynamic, int Nr = Eigen::Dynamic, int Nl = Eigen::Dynamic>
class ConstrainedMechanism : public ConstrainedSystem {
 public:
  using Problem = ConstrainedProblemT<Nj, Nr, Nl>;
  using Solution = ConstrainedSolutionT<Nj, Nr, Nl>;
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;
  // The state's size when the instantiation fixes it (n + k), else Dynamic: copies of q and v at that
  // size unroll (fixed_size_copy.h setFixed), here and in the engines that hold a state.
  static constexpr int kState = Nj == Eigen::Dynamic || Nl == Eigen::Dynamic ? Eigen::Dynamic : Nj + Nl;

  // Throws std::invalid_argument when the description does not validate or does not fit the sizes.
  explicit ConstrainedMechanism(MechanismModel<S> model);

  const MechanismModel<S>& model() const { return model_; }
  // Fixed by the instantiation where it fixes them (the constructor checks the model fits).
  int n() const { return Nj == Eigen::Dynamic ? model_.treeDof() : Nj; }
  int k() const { return Nl == Eigen::Dynamic ? model_.payloadDof() : Nl; }
  int rows() const { return rows_; }
  // True when every constraint has a position form (no velocity-level kind such as rolling).
  bool holonomic() const {
    for (const auto& c : model_.constraints)
      if (!c->holonomic()) return false;
    return true;
  }

  // ConstrainedSystem
  // q: the trees' configuration (nq numbers: a quaternion per ball, chain.h) then the payloads'; v: n + k rates.
  int nqTree() const { return Nj == Eigen::Dynamic ? model_.tree.nq() : Nj; }
  int nq() const override { return nqTree() + k(); }
  int nv() const override { return n() + k(); }
  void configurationRate(const VecN& q, const VecN& v, VecN& qdot) override;
  void integrateConfiguration(VecN& q, const VecN& dx, double h) override;
  void normalizeConfiguration(VecN& q) override;
  void accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a) override;
  void constraint(const VecN& q, VecN& phi, MatN& G) override;
  void baumgarteTerm(const VecN& q, const VecN& v, double zeta, double omega, VecN& s) override;
  void metric(const VecN& q, MatN& W) override;
  bool correction(const VecN& q, const VecN& e, VecN& dx) override;
  void setTime(double t) override;
  void derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a, double& work,
                   double& friction) override;

  // The full solve at a state (τ: n tree torques, or n + k: then also generalised forces w on the
  // payload coordinates, an external push: M_c α_c + b_c + G_c = Aᵀ f + w): α_c, η, f and θ''. Remembered: the integrator's
  // next first stage at the same (q, v, τ) reuses it.
  Solution solve(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab = nullptr);

  // The force constraint i applies (body a on body b, world axes at its point) in a solution.
  Vec constraintForce(int i, const Solution& s);
  // Its η rows, and the row where they start.
  int rowOffset(int i) const { return offsets_[std::size_t(i)]; }
  // The load each tree joint carries in a solution s at (q, v): the spatial force the joint's parent
  // applies to the subtree it carries, world axes at the world origin (spatial: (moment, force)).
  // RNEA (chain.h) at θ'' with gravity gives the force the subtree's motion needs; the constraint
  // forces on the subtree's links supply part of it, the joint the rest:
  //   f_i = Σ_{k ∈ subtree(i)} (I_k a_k + v_k ×* I_k v_k − I_k a_g)  −  Σ_{constraints on the subtree} f_c
  // Its part along the joint's axis is the joint's torque net of spring and friction; the rest is what
  // the bearing carries. The description's external forces (model().forces) are not counted.
  void jointLoads(const VecN& q, const VecN& v, const Solution& s, std::vector<Vec>& loads);
  // Constraint i's extra reports (Constraint::reportNames) at the state last solved.
  void constraintReport(int i, const Solution& s, double* out);

  // Energy: kinetic and gravity of trees and payloads, and joint springs.
  double energy(const VecN& q, const VecN& v);
  double kineticEnergy(const VecN& q, const VecN& v);
  double potentialEnergy(const VecN& q);
  // Unilateral contacts (Constraint::unilateral), between steps: closes every open rigid contact that
  // has reached its plane moving into it, with a plastic impact (v projected onto the closed rows: eq.
  // (2) for impulses), then opens closed ones whose solved η would pull, one at a time (most negative
  // first), until every closed one presses. Returns how many changed; v changes only on impact.
  int updateContacts(const VecN& q, VecN& v, const VecN& tau);
  // One integrator step (dyn::step) with its touchdowns located: when an open rigid unilateral contact
  // ends the step past its plane (φ > 0), the step is retaken from its start to the crossing — the
  // sub-step h with φ(h) = 0, by regula falsi (Illinois) on h, landing within kTouchdownDepth past the
  // plane — the contact closed there by updateContacts (its plastic impact, then the lift-off check),
  // and the rest of the step taken from there. A step without a crossing costs one look at φ of the
  // open contacts at its end (the projection's own position stage). False if the integrator failed.
  bool stepLocatingContacts(const StepOptions& options, const VecN& tau, VecN& q, VecN& v) {
    // Every contact closed (or none): the plain step, inline (the usual case).
    return anyOpenContact() ? stepToTouchdowns(options, tau, q, v) : dyn::step(*this, options, tau, q, v);
  }
  // The impulse (N·s; as constraintForce: body a on body b, world axes at its point) that the plastic
  // impact of the last updateContacts gave constraint i: ∫ f dt over the impact, P = Λ_n v_n for one
  // contact alone; zero when that call closed nothing (or the solve was singular). A lab that reports a
  // step's mean contact force, as impulse-based engines do, adds P/dt to the solved force.
  const Vec& impactImpulse(int i) const { return impact_[std::size_t(i)]; }
  // The kinetic energy every plastic impact of updateContacts has taken since construction (J, ≥ 0):
  // ½ Δvᵀ M Δv each (v⁺ is v⁻'s M-orthogonal projection onto the closed rows, so v⁺ᵀ M Δv = 0) — what
  // an energy book adds to E − E0 − W to balance a run with touchdowns.
  double impactLoss() const { return impact_loss_; }
  // False while constraint i's rows are released (an open unilateral or a compliant contact).
  bool closed(int i) const { return !released_[std::size_t(i)]; }
  // Close or open a unilateral constraint by hand (initial conditions, tests).
  void setClosed(int i, bool closed);

  // |φ|∞ over every holonomic constraint (velocity-level kinds: |J θ' − A v_c|∞ needs v: residual(q, v)).
  double residual(const VecN& q);
  double residual(const VecN& q, const VecN& v);
  // |φ_i|∞ of constraint i alone.
  double residual(int i, const VecN& q);

  // For controllers, at θ (and θ'; the full q and v work too): world position, Jacobian J (S::kDim × n)
  // and J'θ' of a point of a link.
  Pos pointPosition(int link, const Pos& point, const VecN& q);
  void pointJacobian(int link, const Pos& point, const VecN& q, const VecN& qd, MatN& J, VecN& Jdot_qd);
  MatN massMatrix(const VecN& q);                       // M(θ)
  VecN gravityTorque(const VecN& q);                    // G(θ) (+ springs, with with_springs)
  VecN inverseDynamics(const VecN& q, const VecN& qd, const VecN& qdd);  // M θ'' + C θ' + G (no springs, friction)
  // Λ = (J M⁻¹ Jᵀ)⁻¹ for a task Jacobian J (rows × n); empty when J M⁻¹ Jᵀ is singular.
  MatN operationalInertia(const VecN& q, const MatN& J);
  // e_k's index when the trees move in the plane ⊥ e_k (chain_planar_in_space.h: M, h and the kinetic
  // energy on their in-plane components), else −1. Spatial only; found once, at construction.
  int planeNormal() const { return planar_.axis; }
  // The kinematics of the state last staged (constraint kinds read it; so may drawing code).
  const MechanismKinematics<S>& kinematics() const { return kin_; }
  // Stages a configuration (and rates) explicitly, for queries on kinematics().
  void stage(const VecN& q, const VecN* v = nullptr);

 protected:
  // The projection, the trace row and the next step's first stage revisit the same configuration:
  // checked here, inline, so that a revisit costs a comparison.
  void positionStage(const VecN& q) {
    if (!have_position_ || !same(q, staged_q_)) stagePosition(q);
  }
  // a == b (sizes too), entry by entry as Eigen's ==; unrolled at fixed sizes: the stages' cache checks
  // run several times a step, and Eigen's loop over a bounded size costs more than the comparison.
  static bool same(const VecN& a, const VecN& b) {
    if constexpr (kState != Eigen::Dynamic)
      if (a.size() == kState && b.size() == kState) {
        bool equal = true;
        for (int i = 0; i < kState; ++i) equal = equal && a[i] == b[i];
        return equal;
      }
    return a.size() == b.size() && a == b;
  }
  // With qd (stageBoth), h = C θ' + G too, in CRBA's pass; velocityStage then with h_staged.
  void stagePosition(const VecN& q, const VecN* qd = nullptr);
  void velocityStage(const VecN& v, bool h_staged = false);
  // Both stages at (q, v) where the position is not staged at q: on a 6-D serial chain without a
  // payload (fused_), CRBA and the bias forces in one pass (chain_sized.h crbaAndBiasSerial).
  void stageBoth(const VecN& q, const VecN& v);
  // stageBoth when the position staged is not q's (true); false, and nothing staged, when it is. The
  // one test of a new position for the callers that have the rates (stage, evaluate, updateContacts).
  bool stageBothIfNew(const VecN& q, const VecN& v) {
    if (have_position_ && same(q, staged_q_)) return false;
    stageBoth(q, v);
    return true;
  }
  // The tree's transforms alone at θ (controller queries), cached like the position stage.
  void treeStage(const VecN& q);
  // The solve at a state; without with_qdd, α_c, η and f only (θ'' left unset); without with_forces,
  // θ'' and α_c only (η and f as the solve left them: the closed rows' alone when selected).
  Solution evaluate(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, bool with_qdd = true, bool with_forces = true);
  // The deepest φ (= −gap) of the open rigid unilateral contacts at q, −∞ if none is open. Each φ as
  // the position stage computes it: from the stage at q (made here if need be, or with `stage` always);
  // without `stage`, when every rigid contact is a joint limit and the stage is elsewhere, from q alone
  // (the stage in place, e.g. a located step's start, stays).
  double openDepth(const VecN& q, bool stage = false);
  // True while a rigid unilateral contact is open; stepLocatingContacts with one open.
  bool anyOpenContact() const {
    if (!any_rigid_contact_) return false;
    for (std::size_t i = 0; i < released_.size(); ++i)
      if (rigid_contact_[i] && released_[i]) return true;
    return false;
  }
  bool stepToTouchdowns(const StepOptions& options, const VecN& tau, VecN& q, VecN& v);
  // The velocity change dx = (dθ, dx_c) an impulse makes at the staged configuration (factored):
  // eq. (2) for impulses with J dθ − A dx_c = e; its impulses in s. False if dx is not finite.
  bool impulseResponse(const VecN& e, Solution& s, VecN& dx);
  // M_ii += a_i: the rotors' reflected inertia (armature) on the diagonal of a tree mass matrix.
  template <class Mat>
  void addArmature(Mat& M) const {
    if (!has_armature_) return;
    const int nn = n();
    for (int i = 0; i < nn; ++i) M(i, i) += model_.joints[std::size_t(i)].armature;
  }
  // Forget every cached stage (the released rows changed).
  void invalidate() { have_position_ = have_velocity_ = have_last_ = false; }

  MechanismModel<S> model_;
  int rows_ = 0;
  std::vector<int> offsets_, row_count_;  // per constraint: its first row, its rows (Constraint::rows)
  std::vector<int> row_owner_;            // per row: its constraint
  TreeData<S> data_;
  PlanarTreeData planar_;  // a spatial tree moving in a plane: its planar kernels' state (axis −1: none)
  MechanismKinematics<S> kin_;
  Problem problem_;
  ConstrainedFactorT<Nj, Nr, Nl> factor_;
  bool factored_ = false;
  // The closed rows alone in the solve while some are released (dynamic sizes): selectClosedRows.
  bool selectClosedRows();
  void limitRows();  // the constructor's: limit_rows_, only_limits_ and their constant rows
  void scatterClosedRows(Solution& s) const;
  template <class Out>
  void gatherClosedRows(const VecN& all, Out& out) const;
  bool selected_ = false;          // problem_ holds the closed rows alone (J̃ = H̃ J, Ã = H̃ A, J'θ', s)
  // Which rows are closed changes (released_ written): closed_version_ counts the changes; while every
  // constraint is a joint limit (J constant), problem_'s J̃ and Ã stay those selected at
  // selected_version_ (−1: problem_ holds something else).
  int closed_version_ = 0, selected_version_ = -1;
  // Joint limits (constraints/joint_limit.h: φ = −σ (θ_i − θ_bound), J = −σ e_iᵀ, constant): per
  // constraint its coordinate in q and column, σ and the bound (coordinate −1: another kind). With
  // only limits (the PUMA file's twelve rows), J_full_ and A_full_ are written once, at construction,
  // and a position stage computes each row's φ alone, without a virtual call.
  struct LimitRow {
    int coordinate = -1, column = -1;
    double sign = 0, bound = 0;
    // φ = −σ (θ_c − θ_bound), JointLimit::position's: how far past its stop, from θ (or q: its tree part
    // first). The one definition the position stage and openDepth's shortcut share.
    template <class Theta>
    double phi(const Theta& theta) const {
      return -(sign * (theta[coordinate] - bound));
    }
  };
  std::vector<LimitRow> limit_rows_;
  bool only_limits_ = false;
  // Every rigid contact is a joint limit: openDepth may read their φ from q (limit_rows_).
  bool depth_from_q_ = false;
  // What the position stage found of the rigid contacts (released_ does not change under a stage: a
  // change invalidates it): the deepest φ of the open ones (−∞: none open) and whether any is closed.
  // openDepth at the staged q and updateContacts' touchdown check read them. The limits alone find them
  // in their φ pass; other kinds when first asked (rigid_known_ false: rigidContactsAtStage).
  double open_depth_ = 0;
  bool rigid_closed_ = false, rigid_known_ = false;
  void rigidContactsAtStage();  // the two from the stage's phi_full_
  // The position stage at q with the two known (updateContacts' touchdown check, openDepth); with the
  // rates v, a new position staged with them (stageBothIfNew).
  void stagedContacts(const VecN& q, const VecN* v = nullptr) {
    if (v) stageBothIfNew(q, *v);
    else positionStage(q);
    if (!rigid_known_) rigidContactsAtStage();
  }
  void limitRowsAtStage();      // the limits' φ pass (only_limits_), the two with it
  bool selected() const { return Nr == Eigen::Dynamic && selected_; }  // never at fixed rows (a lab's)
  // The closed rows selected all lock a coordinate (J̃ row = −σ e_cᵀ, distinct c, no payload: joint limits
  // at their stops): solved by elimination (constrained_solve.h factorLocked), their c and σ here.
  bool locked_rows_ = false;
  std::vector<int> lock_coordinate_;
  std::vector<double> lock_sign_;
  bool lockedCoordinates();  // sets the three from problem_.J (selectClosedRows)
  bool factorClosedRows();   // the selected rows' factor: by elimination where they lock coordinates
  std::vector<int> closed_rows_;   // their rows, in order
  VecN phi_;
  VecN gravity_bc_;    // b_c + G_c of the payloads without external forces (b_c = 0: world axes at the centre of mass)
  VecN staged_q_;      // the configuration of the position stage
  bool have_position_ = false;
  VecN staged_v_;      // the rates of the velocity stage (at staged_q_)
  bool have_velocity_ = false;
  std::vector<double> tree_angle_;  // planar: each placement's fixed rotation angle
  VecN tree_q_;        // the θ that data_'s transforms are at
  bool have_tree_ = false;
  VecN last_tau_;      // the last solve without stabilisation: at the staged (q, v) and this τ
  Solution last_;
  bool have_last_ = false;
  // Unilateral and compliant kinds: which constraints are released, their rows before the release
  // (φ, J, A: gaps and compliant forces read them), and the compliant forces of the velocity stage.
  std::vector<char> released_;
  std::vector<char> compliant_, rigid_contact_;  // per constraint: a compliant contact; a rigid unilateral one
  bool any_released_kind_ = false, any_compliant_ = false, any_rigid_contact_ = false;
  VecN phi_full_;
  MatN J_full_, A_full_;
  VecN compliant_eta_;   // per row: the compliant force η (0 elsewhere)
  VecN compliant_bc_;    // payload side: −Aᵀ η of the compliant rows
  std::vector<Vec> impact_;  // per constraint: the last updateContacts' impact impulse
  bool any_impact_ = false;
  double impact_loss_ = 0.0;  // J, the impacts' kinetic energy taken so far
  // External forces (at the velocity stage's time): the payloads' share Aᵀ F of b_c + G_c, their power
  // F·V_P; and the joint friction's power.
  VecN external_bc_;
  double external_power_ = 0, friction_power_ = 0;
  bool has_forces_ = false;  // the model has external forces (fixed at construction)
  bool has_armature_ = false;  // some joint has armature (fixed at construction): M_ii += a_i
  bool fused_ = false;  // stageBoth's one pass fits the tree (fixed at construction)
};

}  // namespace dyn
