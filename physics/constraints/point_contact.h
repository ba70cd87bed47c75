// Point contact with friction (lecture §2 eq. (3), §3 "Multi-finger grasp"): a point of body a (a
// fingertip) presses on a point of body b (the object) whose surface there has the outward normal n
// (in b's frame). The contact passes a force and no moment: the relative rotation is free,
//   planar   H = (1, 0, 0),  H̃ = [[0, 1, 0], [0, 0, 1]]     (spatial: H spans the three rotations)
//   rows     H̃ (V_a(P_a) − V_b(P_b)) = 0: the point rows of point_closure.h. H and H̃ are constant in
//            world axes, so H̃'J θ' = 0 and H'w drops out of (3) (H̃ H = 0).
//   force    f = H̃ᵀ η (a on b, at P_b), in contact axes: normal f_n = −f·n (pressing is positive: the
//            finger pushes into b), tangential f_t = f·t, t = ẑ × n (spatial: |f − (f·n) n|)
//   cone     margin μ f_n − |f_t|: ≥ 0 inside the friction cone; the contact would slip (or pull) below 0.
// The contact is bilateral here (it holds whatever the sign of f_n): the margin says when a real
// contact would have let go.
#pragma once
#include "physics/constraints/point_closure.h"

namespace dyn {

// The rows, their force and point are the point closure's (translations only); a contact adds its kind,
// its axes and its report.
template <class S>
class PointContact final : public PointClosure<S> {
 public:
  using Pos = typename S::Pos;

  // normal_b: b's outward surface normal at point_b, in b's frame; mu ≥ 0.
  PointContact(BodyRef a, const Pos& point_a, BodyRef b, const Pos& point_b, const Pos& normal_b, double mu);

  const char* kind() const override { return "point_contact"; }
  // f_n, f_t, cone margin.
  std::vector<std::string> reportNames() const override { return {"f_n", "f_t", "cone_margin"}; }
  void report(const MechanismKinematics<S>& k, const double* eta, double* out) const override;

  double mu() const { return mu_; }
  // f_n, f_t and the cone margin μ f_n − |f_t| of a force f (a on b, world axes) at a contact whose
  // outward normal (b's, world axes) is n: what report() writes, for forces from elsewhere (Bullet's).
  static void contactAxes(const Pos& f, const Pos& n, double mu, double* out);
  // The world outward normal of b at the contact.
  Pos normal(const MechanismKinematics<S>& k) const;

 private:
  Pos normal_b_;
  double mu_;
};

}  // namespace dyn
