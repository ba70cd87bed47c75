// Point closure: a point of body a held on a point of body b along chosen world axes, and optionally
// their relative angle — a loop closure (the slider crank's tip on its slider), a rigid grip, a pin
// to the world. With S the selection of rows of the spatial motion vector (planar (ω, x, y)):
//   φ       = S (ψ_a − ψ_b, p_a − p_b)             (angle wrapped to [−π, π]; spatial: the rotation
//                                                  vector of R_a R_bᵀ, p_a − p_b)
//   J θ' − A v_c = S (V_a(P_a) − V_b(P_b))          V_x(P): velocity of a world-aligned frame at P on x
//   J'θ' − A'v_c = S (a_a(P_a) − a_b(P_b))          a_x(P): its classical acceleration at θ'' = 0, α_c = 0
//   f (a on b)   = Sᵀ η, at P_b
// Every row constrains motion, none is free: H is empty (eq. (2)). A point contact (point_contact.h)
// is the same rows with the rotation left free.
#pragma once
#include "physics/mechanism.h"

namespace dyn {

template <class S>
class PointClosure : public Constraint<S> {  // a point contact (point_contact.h) is one
 public:
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;
  using Rows = std::array<bool, S::kDim>;

  // rows: which of (ω, x, y) (spatial (ωx, ωy, ωz, x, y, z)) are held, world axes.
  PointClosure(BodyRef a, const Pos& point_a, BodyRef b, const Pos& point_b, const Rows& rows);
  // Every row: a weld. Translations only: a pin.
  static Rows all();
  static Rows translations();

  const char* kind() const override { return "point_closure"; }
  int rows() const override { return count_; }
  void position(const MechanismKinematics<S>& k, int row, VecN& phi, MatN& J, MatN& A) const override;
  void bias(const MechanismKinematics<S>& k, int row, VecN& b) const override;
  Vec force(const MechanismKinematics<S>& k, const double* eta) const override;
  Pos point(const MechanismKinematics<S>& k) const override { return k.position(at_.b, at_.point_b); }
  Attachment<S> attachment() const override { return at_; }

 private:
  Attachment<S> at_;
  int count_ = 0;
  bool turns_ = false;  // a rotation row is held (planar: ω; spatial: any of ωx, ωy, ωz)
};

}  // namespace dyn
