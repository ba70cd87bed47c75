// Multi-finger grasp (lecture §3, eq. (3)) described as data: planar fingers, each a chain of two
// revolute links on a fixed base (a tree hanging from the world), hold one rigid object (a payload
// with its own Newton–Euler equation, pose (ψ, x, y) of its centre of mass) through point contacts
// with friction (physics/constraints/point_contact.h: the contact passes (f_x, f_y) and no moment):
//   q = (θ_1 … θ_n, ψ, x, y),   finger i:  J_i θ_i' + H_i w_i = A_i v_c,   A_i = Φ(p_ci),   H_i = (1, 0, 0)
//   object   M_c α_c + G_c = Σ_i A_iᵀ f_i = W(f)     (W: the grasp map, below)
// With m fingers of two joints each: 2m joints, 3 object coordinates, 2m rows: the object's pose is
// the motion, and 2m − 3 directions of contact force move nothing: the internal forces, N(Aᵀ).
// physics/ does the rest (the generic mechanism, eq. (3), both engines). What is particular stays here:
// the inverse kinematics that assembles the fingers on the object, and the grasp map.
//   grasp map   W = G F,   F = (f_1x, f_1y, …, f_mx, f_my),   G's block i = [[−r_iy, r_ix], [1, 0], [0, 1]]
//               (r_i = p_ci − x_o: the moment, then the force, the object receives)
//   squeeze     d = (I − G⁺G) e,  e = the stacked inward contact normals: forces along d move nothing;
//               the internal force f_int = d·F / d·d (each contact's share of squeeze, N; for two
//               opposed contacts d = e and f_int is the common normal force).
#pragma once
#include <vector>

#include "physics/constrained_mechanism.h"

namespace dyn::grasp {

struct Link {
  double length, mass, inertia;  // m, kg, kg·m² about the centre of mass (at mid-length)
};

struct Finger {
  Eigen::Vector2d base;                            // world, m
  std::vector<Link> links;                         // exactly two
  int elbow = 1;                                   // sign of the second joint angle θ_2 (the elbow branch)
  Eigen::Vector2d contact = Eigen::Vector2d::Zero();  // the held point, object frame
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();  // the object's outward surface normal there, object frame
};

struct Object {
  double mass = 0.2, inertia = 8.7e-5;     // kg, kg·m² about the centre of mass
  Eigen::Vector2d size{0.06, 0.04};        // m, drawing only (the contacts are the fingers' points)
};

struct Params {
  std::vector<Finger> fingers;
  Object object;
  JointProperties joint;                   // every finger joint's friction (viscous, Coulomb); the controller does not know it
  double mu = 0.6;
  Eigen::Vector2d gravity{0.0, -9.81};     // world, m/s²
  std::vector<ExternalForcePtr<Planar>> forces;  // external forces (the lab's push on the object)
};

// The description both engines are built from.
MechanismModel<Planar> describe(const Params& params);

// Eq. (3) at bounded sizes (the finger count comes from the JSON).
class Mechanism final : public ConstrainedMechanism<Planar> {
 public:
  explicit Mechanism(const Params& params);

  int fingers() const { return int(params_.fingers.size()); }
  // Joint index of finger i's first joint.
  static int joint(int finger) { return 2 * finger; }
  // A consistent state: the object at pose (ψ, x, y) with rate (ω, v_x, v_y), each finger's tip on its
  // contact by inverse kinematics on its elbow branch. False (and `why` says which finger) if a
  // contact point is out of a finger's reach.
  bool assemble(const Eigen::Vector3d& pose, const Eigen::Vector3d& rate, VecN& q, VecN& v, std::string* why = nullptr) const;
  // Independent coordinates (the object's pose): rebuild the fingers from it on their current branches.
  bool recoverDependent(VecN& q, VecN& v) override;

  // World positions of contact i on the object at pose (ψ, x, y), and of finger i's joints and tip at q.
  Eigen::Vector2d contactPoint(int i, const Eigen::Vector3d& pose) const;
  // The object's outward unit normal at contact i, world axes, at tilt ψ.
  Eigen::Vector2d contactNormal(int i, double psi) const;
  std::vector<Eigen::Vector2d> fingerPoints(int i, const VecN& q) const;  // base, elbow, tip
  // The grasp map G (3 × 2m) and the squeeze direction d (2m) at object pose (ψ, x, y).
  void graspMap(const Eigen::Vector3d& pose, MatN& G, VecN& d) const;
  // The internal force of stacked contact forces F (on the object, world axes): d·F / d·d.
  double internalForce(const Eigen::Vector3d& pose, const VecN& F) const;
  // The fingertips' stacked translational Jacobian (2m × n) at θ.
  MatN tipJacobian(const VecN& q);
  const Params& params() const { return params_; }

 private:
  Params params_;
};

// The plant at the default two fingers' sizes (4 joints, 4 contact rows, the object's 3 coordinates):
// the step's loops unrolled, as the other labs fix theirs; its inverse kinematics Mechanism's.
class TwoFingers final : public ConstrainedMechanism<Planar, 4, 4, 3> {
 public:
  explicit TwoFingers(const Params& params);
  bool recoverDependent(VecN& q, VecN& v) override { return shape_.recoverDependent(q, v); }
  // The dynamically sized mechanism it keeps for the fingers' geometry (assemble, the grasp map).
  const Mechanism& shape() const { return shape_; }

 private:
  Mechanism shape_;
};

}  // namespace dyn::grasp
