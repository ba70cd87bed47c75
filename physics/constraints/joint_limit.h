// A joint limit (MuJoCo's jnt_range with limited="true"; URDF <limit lower upper>): one side of the
// range [θ_lo, θ_hi] of tree joint i (a hinge's angle in rad, a slide's travel in m), a one-sided row
// handled by the mechanism exactly as the pen's contact with the table (plane_contact.h):
//   gap      g = θ_i − θ_lo (lower side, σ = +1)   or   g = θ_hi − θ_i (upper side, σ = −1),
//            i.e. g = σ (θ_i − θ_bound)
//   row      φ = −g,   J θ' = −σ θ'_i              (J = −σ e_iᵀ: positive when the joint runs into the stop)
//   bias     J'θ' = 0                             (J is constant)
//   force    the generalised force −Jᵀη = σ η e_i on the joint: η ≥ 0 pushes it back into its range. As
//            a spatial force the parent applies to the child at the joint's anchor: σ η a (a moment
//            about a hinge's axis a, a force along a slide's), world axes.
// The rigid stop holds g ≥ 0, η ≥ 0, g η = 0: the mechanism closes the row when the joint reaches its
// stop moving into it (a plastic impact: the least-kinetic-energy velocity that keeps every closed row,
// the joint's rate into the stop dropping to 0), keeps
// it while η presses and opens it when η would pull; a crossing inside a step is located (regula falsi)
// and closed there, so no step ends past the stop by more than the locator's tolerance.
// MuJoCo's own limit is soft (solref/solimp: a stiff spring-damper past the stop, no event): a joint
// resting on its stop sits a little past it there, by about m g / k_eff (tests/ measure it).
#pragma once
#include "physics/mechanism.h"

namespace dyn {

class JointLimit final : public Constraint<Spatial> {
 public:
  using Vec = Spatial::Vec;
  using Pos = Spatial::Pos;
  enum class Side { Lower, Upper };

  // joint: a tree joint (body index); parent: its tree parent (−1: the world); bound: θ_lo or θ_hi.
  // Throws std::invalid_argument on a bad value.
  JointLimit(int joint, int parent, Side side, double bound);

  const char* kind() const override { return "joint_limit"; }
  int rows() const override { return 1; }
  bool unilateral() const override { return true; }
  void position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const override;
  void bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const override;
  Vec force(const MechanismKinematics<Spatial>& k, const double* eta) const override;
  Pos point(const MechanismKinematics<Spatial>& k) const override;
  Attachment<Spatial> attachment() const override;
  // gap (rad or m), f_n = η (N·m or N, ≥ 0 pressing).
  std::vector<std::string> reportNames() const override { return {"gap", "f_n"}; }
  void report(const MechanismKinematics<Spatial>& k, const double* eta, double* out) const override;

  // g at a state's kinematics (position stage).
  double gap(const MechanismKinematics<Spatial>& k) const { return sign() * (k.theta[k.model ? k.model->tree.bodies[std::size_t(joint_)].q_index : joint_] - bound_); }
  // η from a spatial force this limit applies (force()'s inverse: σ a · the moment or force).
  double along(const MechanismKinematics<Spatial>& k, const Vec& f) const;
  int joint() const { return joint_; }
  Side side() const { return side_; }
  double bound() const { return bound_; }
  double sign() const { return side_ == Side::Lower ? 1.0 : -1.0; }

 private:
  int joint_, parent_;
  Side side_;
  double bound_;
};

}  // namespace dyn
