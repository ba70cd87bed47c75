// Rolling without slip (lecture §3 "Unicycle"): a disk of radius r on body b (centre c_b, axle a_b in
// b's frame) rolls on the ground plane z = h; the ground is body a (the world). The disk touches the
// ground at its lowest point
//   d = u / |u|,  u = n − (n·a) a         (n = ẑ, a the world axle: d is "down" in the disk's plane)
//   P = p − r d                          (p the disk centre)
// and the wheel's material point at P is at rest: three rows, world axes x, y, z,
//   J θ' − A v_c = −(v_p + ω × (P − p))                     (the material point's velocity at P)
// Only the z row has a position form, φ_z = h − P_z (the envelope of the rim: its rate is the material
// point's normal velocity); the x, y rows are velocity-level — nonholonomic, no φ exists — so they
// write φ = 0: Baumgarte keeps only its −2ζω(Jθ' − A v_c) term there, the projection corrects their
// velocities only. Differentiating the rows, P moves along the rim (it is not a material point), so
//   J'θ' − A'v_c = −(a_p + ω' × (P − p) + ω × (Ṗ − ṗ)),  Ṗ − ṗ = −r ḋ,
//   ḋ = (u' − d (d·u')) / |u|,  u' = −(n·a') a − (n·a) a',  a' = ω × a
// with a_p, ω' the θ'' = 0 parts: the material point's classical acceleration without its
// centripetal ω × (ω × (P − p)) — exactly what keeps the lateral force at m v φ' for an upright wheel.
//   force  f = (0, η) on the wheel at P, world axes; in wheel axes e_lat (the axle, horizontal),
//          e_long = e_lat × n (heading), n: f_long, f_lat, f_normal = f·e
//   skid   margin μ f_normal − |(f_long, f_lat)|: a friction contact would skid below 0.
#pragma once
#include "physics/mechanism.h"

namespace dyn {

class Rolling final : public Constraint<Spatial> {
 public:
  using Vec = Spatial::Vec;
  using Pos = Spatial::Pos;

  // wheel: a link; centre_b, axle_b in its frame; radius > 0; the ground z = ground_height; mu ≥ 0
  // (only for the skid report). Throws std::invalid_argument on a bad value.
  Rolling(BodyRef wheel, const Pos& centre_b, const Pos& axle_b, double radius, double ground_height, double mu);

  const char* kind() const override { return "rolling"; }
  int rows() const override { return 3; }
  bool holonomic() const override { return false; }
  void position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const override;
  void bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const override;
  Vec force(const MechanismKinematics<Spatial>& k, const double* eta) const override;
  Pos point(const MechanismKinematics<Spatial>& k) const override;
  Attachment<Spatial> attachment() const override;
  // f_long, f_lat, f_normal (N), skid margin (N), slip: the contact's material speed along the ground (m/s).
  std::vector<std::string> reportNames() const override { return {"f_long", "f_lat", "f_normal", "skid_margin", "slip"}; }
  void report(const MechanismKinematics<Spatial>& k, const double* eta, double* out) const override;

  // The wheel's axes at a world axle direction: e_long, e_lat, n (columns).
  static Eigen::Matrix3d wheelAxes(const Pos& axle_world);
  // f_long, f_lat, f_normal and the skid margin of a ground force f on the wheel (world axes), for
  // forces from elsewhere (Bullet's): what report() writes first.
  static void contactAxes(const Pos& f, const Pos& axle_world, double mu, double* out);

  BodyRef wheel() const { return wheel_; }
  const Pos& centre() const { return centre_b_; }
  const Pos& axle() const { return axle_b_; }
  double radius() const { return radius_; }
  double groundHeight() const { return ground_; }
  double mu() const { return mu_; }

 private:
  struct Geometry {
    Pos p, a, u, d, P;  // centre, world axle, u, down, contact point
    double un;          // |u|
  };
  Geometry geometry(const MechanismKinematics<Spatial>& k) const;

  BodyRef wheel_;
  Pos centre_b_, axle_b_;
  double radius_, ground_, mu_;
};

}  // namespace dyn
