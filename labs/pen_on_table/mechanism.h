// The pen-on-table arm (lecture §3 "Pen on table") described as data: a spatial 3-DOF elbow arm
//   joint 1  revolute about the vertical z at the base; link 1 a vertical column of height h1
//   joint 2  pitch, revolute about link 1's y at the column's top; link 2 of length l2 along its x
//   joint 3  pitch, revolute about link 2's y at its end;          link 3 of length l3 along its x
// The pen's tip is a ball of radius ρ centred at link 3's end. Positive pitch turns x towards −z, so
// with φ2 = −θ2 and φ3 = −θ3 (angles up from the horizontal) the tip's ball centre is
//   c = (R cos θ1, R sin θ1, h1 + Z),  R = l2 cos φ2 + l3 cos(φ2 + φ3),  Z = l2 sin φ2 + l3 sin(φ2 + φ3).
// The table is the plane z = z_t under a unilateral contact (physics/constraints/plane_contact.h):
// gap = c_z − ρ − z_t ≥ 0, η ≥ 0 the table's push on the pen along ẑ, frictionless in the hand model;
// rigid, or compliant (stiffness k_e, damping d_e: η = max(0, k_e d + d_e d'), d the depth).
// The pen tip p is the ball's lowest point, c − ρ ẑ: on the table when z_p = z_t; its velocity is c's.
// Eq. (3) with the contact closed: M θ'' + C θ' + G = τ − J_cᵀ ẑ η, ẑ·(J_c θ'' + J_c'θ') = 0.
#pragma once
#include <array>

#include "physics/constrained_mechanism.h"

namespace dyn::pen_on_table {

// A link as a solid cylinder (its inertia, and how it is drawn).
struct Link {
  double length = 0.3;  // m
  double mass = 1.0;    // kg
  double radius = 0.02; // m
};

struct Params {
  std::array<Link, 3> links{Link{0.3, 2.0, 0.04}, Link{0.3, 1.5, 0.025}, Link{0.35, 1.0, 0.02}};
  double tip_radius = 0.005;  // m, ρ: the pen tip's ball
  double pen_load = 0.0;      // kg, a point mass at the tip (a heavier pen: the controller's model omits it)
  double gravity = 9.81;      // m/s², along −z
  double table_height = 0.1;  // m, z_t
  double table_stiffness = 0; // N/m, k_e (0: rigid)
  double table_damping = 0;   // N·s/m, d_e (compliant only)
  double mu = 0;              // Coulomb friction: Bullet's contact only (the hand model is frictionless)
};

// The description both engines are built from.
MechanismModel<Spatial> describe(const Params& params);

// Eq. (3) at the arm's fixed sizes: 3 joints, 1 contact row, no payload.
class Mechanism final : public ConstrainedMechanism<Spatial, 3, 1, 0> {
 public:
  explicit Mechanism(const Params& params);
  const Params& params() const { return params_; }
  // The pen tip p = c − ρ ẑ (world) at θ, by the tree's own kinematics.
  Eigen::Vector3d tip(const VecN& q);
  // p and its 3 × 3 translational Jacobian (v_p = J θ'), and J'θ'.
  void tipJacobian(const VecN& q, const VecN& v, Eigen::Vector3d& p, Eigen::Matrix3d& J, Eigen::Vector3d& Jdot_v);
  // The table's gap z_p − z_t (negative: the tip is that deep in a compliant table).
  double gap(const VecN& q) { return tip(q).z() - params_.table_height; }
  // Link 3's end (the ball centre) as a link point, and link 3's index in the tree.
  static Spatial::Pos tipPoint(const Params& p) { return {p.links[2].length, 0, 0}; }
  static constexpr int kPenLink = 2;

 private:
  Params params_;
};

// Closed-form kinematics of the same arm (the tests' independent check and the initial pose).
//   forward: the pen tip p at θ
//   inverse: θ with the tip at p on the elbow-up branch (the elbow above the shoulder–tip line);
//            false when p is out of reach or on the base axis (θ1 undefined)
Eigen::Vector3d forwardKinematics(const Params& params, const Eigen::Vector3d& theta);
bool inverseKinematics(const Params& params, const Eigen::Vector3d& p, Eigen::Vector3d& theta);
// sin of the elbow angle at a tip position (1: elbow at 90°, 0: stretched or folded: singular).
double elbowSine(const Params& params, const Eigen::Vector3d& p);

}  // namespace dyn::pen_on_table
