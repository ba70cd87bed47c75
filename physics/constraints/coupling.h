// A coupling of coordinates (MuJoCo's <equality><joint> and <equality><tendon> on fixed tendons, as the
// Panda's and the Robotiq 2F-85's fingers are coupled): two linear forms of the tree coordinates,
//   s₁ = a·(θ − θ₀),  s₂ = b·(θ − θ₀)       (a joint: a = e_j; a fixed tendon: its coefficients c_k on
//                                            its joints, s = L(θ) − L(θ₀), L = Σ c_k θ_k its length)
// held to a polynomial, MuJoCo's own form (engine_core_constraint.c, relative to the reference pose θ₀):
//   φ        = s₁ − c₀ − P(s₂),   P(s) = c₁ s + c₂ s² + c₃ s³ + c₄ s⁴     (no second object: φ = s₁ − c₀)
//   J        = aᵀ − P'(s₂) bᵀ,    P'(s) = c₁ + 2 c₂ s + 3 c₃ s² + 4 c₄ s³
//   bias     J'θ' = −P''(s₂) (b·θ')²,  P''(s) = 2 c₂ + 6 c₃ s + 12 c₄ s²
//   force    the generalised force −Jᵀη on the joints (bilateral: η of either sign). It is no single
//            spatial force between two bodies: force() is zero and the trace reports η itself.
// φ(θ₀) = −c₀: the mechanism starts closed only when c₀ = 0 (the loader refuses a file that does not).
#pragma once
#include <vector>

#include "physics/mechanism.h"

namespace dyn {

class Coupling final : public Constraint<Spatial> {
 public:
  using Vec = Spatial::Vec;
  using Pos = Spatial::Pos;
  // A linear form Σ c_k (θ_{j_k} − θ₀_{j_k}) over tree joints (a joint: one term with c = 1).
  struct Term {
    int joint = -1;
    double coef = 0;
  };
  using Form = std::vector<Term>;

  // kind: "joint_coupling" or "tendon_coupling"; first: s₁'s terms (non-empty); second: s₂'s (empty: no
  // second object); poly: c₀ … c₄; q0: θ₀. Throws std::invalid_argument.
  Coupling(const char* kind, Form first, Form second, const std::array<double, 5>& poly, const VecN& q0);

  const char* kind() const override { return kind_; }
  int rows() const override { return 1; }
  void position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const override;
  void bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const override;
  Vec force(const MechanismKinematics<Spatial>& k, const double* eta) const override;
  Pos point(const MechanismKinematics<Spatial>& k) const override;
  Attachment<Spatial> attachment() const override;

  // s of a form at a state (position stage); its rate (velocity stage).
  double value(const MechanismKinematics<Spatial>& k, const Form& f) const;
  static double rate(const MechanismKinematics<Spatial>& k, const Form& f);
  const Form& first() const { return first_; }
  const Form& second() const { return second_; }
  const std::array<double, 5>& poly() const { return poly_; }
  const VecN& reference() const { return q0_; }  // θ₀
  // Linear in one joint each side (c₂ = c₃ = c₄ = 0, single-term forms): what a gear can hold.
  bool linearPair() const;

 private:
  const char* kind_;
  Form first_, second_;
  std::array<double, 5> poly_;
  VecN q0_;
};

}  // namespace dyn
