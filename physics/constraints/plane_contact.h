// A unilateral contact (lecture §3 "Pen on table", §5 "A pen touches, presses, lifts off"): a ball of
// radius ρ centred at c_b on body b (a pen tip, a hand) against the half-space n·x ≥ h of the world
// (a table's top or a wall; n its outward unit normal, world axes). With c the ball's centre (world):
//   gap      g(q) = n·c − ρ − h                  contact point P = c − ρ n (on the plane when g = 0)
//   row      φ = −g,   J θ' − A v_c = −n·v_b(c) = −g'       (positive when the ball approaches; the
//            material point under P has the same normal velocity: n·(ω × ρn) = 0)
//   bias     J'θ' − A'v_c = −n·a_b(c)             (a_b: c's classical acceleration at θ'' = 0)
//   force    f = η n, a pure force on b at P (body a, the world, on b): η ≥ 0 presses
// The tangential motions are free (frictionless: H spans them, H̃ = nᵀ). The rigid contact holds
// g ≥ 0, η ≥ 0, g η = 0: the mechanism keeps it closed (this row of eq. (3)) while its η presses, opens
// it (the row released, η = 0) when η would pull, and closes it with a plastic impact (eq. (2) for
// impulses on the closed rows) when the ball reaches the plane moving into it.
// A compliant plane (stiffness k_e > 0) replaces the row by a force the mechanism applies itself:
//   η = max(0, k_e d + d_e d'),  d = −g the depth
// — as k_e grows this tends to the rigid contact and the time step must shrink with √(m/k_e).
// μ is Coulomb's coefficient for engines that model friction (Bullet's contact); the hand model's
// plane is frictionless.
#pragma once
#include "physics/mechanism.h"

namespace dyn {

struct PlaneContactParams {
  double radius = 0.0;     // m, ρ ≥ 0
  double height = 0.0;     // m, h: the plane is n·x = h
  double mu = 0.0;         // Coulomb friction (Bullet only), ≥ 0
  double stiffness = 0.0;  // N/m, k_e: 0 is rigid
  double damping = 0.0;    // N·s/m, d_e (compliant only)
};

template <class S>
class PlaneContact final : public Constraint<S> {
 public:
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;

  // body: a link or payload; centre_b in its frame; normal: the plane's outward normal (world, any
  // length > 0). Throws std::invalid_argument on a bad value.
  PlaneContact(BodyRef body, const Pos& centre_b, const Pos& normal, const PlaneContactParams& params);

  const char* kind() const override { return "plane_contact"; }
  int rows() const override { return 1; }
  bool unilateral() const override { return true; }
  bool compliant() const override { return params_.stiffness > 0; }
  void position(const MechanismKinematics<S>& k, int row, VecN& phi, MatN& J, MatN& A) const override;
  void bias(const MechanismKinematics<S>& k, int row, VecN& b) const override;
  Vec force(const MechanismKinematics<S>& k, const double* eta) const override;
  Pos point(const MechanismKinematics<S>& k) const override;
  Attachment<S> attachment() const override;
  // The compliant plane's η at a state (velocity stage): max(0, k_e d + d_e d').
  double compliantForce(const MechanismKinematics<S>& k) const override;
  // gap (m), f_n = η (N, ≥ 0 pressing).
  std::vector<std::string> reportNames() const override { return {"gap", "f_n"}; }
  void report(const MechanismKinematics<S>& k, const double* eta, double* out) const override;

  // g(q) at a state's kinematics (position stage).
  double gap(const MechanismKinematics<S>& k) const;
  BodyRef body() const { return body_; }
  const Pos& centre() const { return centre_b_; }
  const Pos& normal() const { return normal_; }  // unit
  const PlaneContactParams& params() const { return params_; }

 private:
  BodyRef body_;
  Pos centre_b_, normal_;
  PlaneContactParams params_;
};

}  // namespace dyn
