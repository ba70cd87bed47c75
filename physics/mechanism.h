// A mechanism described as data (lecture §2): cut it into trees, add the payloads it carries and
// the constraints that close it. physics/ does the rest, in both engines:
//   trees      M θ'' + C θ' + G + K(θ − θ_rest) + B θ' + F_c tanh(θ'/w) = τ + Q_ext − Jᵀ f   (1)
//   payloads   M_c α_c + b_c + G_c = Aᵀ f + Q_ext,c                                        (§2.4)
//   forces     Q_ext = J_Pᵀ F_ext for each external force F_ext at a point P of a body (a push, a
//              spring to the world), evaluated with the motion at every stage of a step
//   closure    J θ' (+ H w) = A v_c, written per constraint kind in the constrained directions (H̃)
// and the generic mechanism (constrained_mechanism.h) solves (2)/(3) for α_c and f together.
//
// Coordinates: q = (θ, x_c), v = (θ', v_c): the tree joints in TreeModel order, then each payload's
// free pose coordinates in its order (planar: ψ, x, y of its centre of mass, world axes).
// Sign convention of every constraint force f: the force body a applies to body b, at the
// constraint's point, world axes, as a spatial force (planar (τ, f_x, f_y)).
#pragma once
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "physics/chain.h"
#include "physics/det/det.h"

namespace dyn {

// A body of the mechanism: the world, a link of the trees, or a payload.
struct BodyRef {
  enum class Kind { World, Link, Payload };
  Kind kind = Kind::World;
  int index = -1;  // link: TreeModel body index; payload: index into payloads
  static BodyRef world() { return {}; }
  static BodyRef link(int i) { return {Kind::Link, i}; }
  static BodyRef payload(int i) { return {Kind::Payload, i}; }
  bool isWorld() const { return kind == Kind::World; }
  bool operator==(const BodyRef&) const = default;
};

// What a tree joint carries beyond its body: a spring about a rest position (the lecture's joint
// flexibility: in relative joint coordinates P_K = Σ k_i/2 (θ_i − θ_rest,i)², which is the
// tridiagonal K of lecture §1 written in absolute angles), viscous friction b θ' and Coulomb
// friction F_c tanh(θ'/w): smoothed over a rate width w, C∞ so that RK4 keeps its fourth order (a
// clamp's kinks at |θ'| = w cost it two orders). Below w it acts as a damper F_c/w; at |θ'| = w it is
// 76 % of F_c, at 3w 99.5 %. Its power −(b θ' + F_c tanh(θ'/w)) θ' is what the books call friction.
// Armature a is a geared rotor's reflected inertia (MuJoCo's armature, J_m G²): M_ii += a, kinetic
// energy ½ a θ'², nothing else (the rotor's own gyroscopic and cross terms are O(1/G), left out).
struct JointProperties {
  double stiffness = 0;      // N·m/rad (N/m for prismatic)
  double rest = 0;           // rad (m)
  double viscous = 0;        // N·m·s/rad
  double coulomb = 0;        // N·m
  double coulomb_width = 1e-2;  // rad/s: w of F_c tanh(θ'/w)
  double armature = 0;          // kg·m² (kg for prismatic): added to M's diagonal (last: positional initialisers keep their order)
  // The friction torque at rate θ' (opposes it: the mechanism subtracts it). tanh(x) rounds to ±1
  // for |x| ≥ 20: the call (the step's most expensive) is skipped there, bit for bit the same.
  double friction(double rate) const {
    if (coulomb == 0) return viscous * rate;
    const double x = rate / (coulomb_width > 0 ? coulomb_width : 1e-12);
    return viscous * rate + coulomb * (std::abs(x) < 20.0 ? det::tanh(x) : std::copysign(1.0, x));
  }
};

// A free body carried by the mechanism (planar): its pose (ψ, x, y) is that of its centre of mass in
// world axes. Coordinates not marked free stay at pose0 (a body on a guide, e.g. the slider crank's
// slider: free = {x}). Its Newton–Euler equation at the centre of mass, world axes:
//   M_c = diag(I, m, m) on the free coordinates,  b_c = 0,  G_c = −m g.
struct Payload {
  std::string name;
  double mass = 1;
  double inertia = 1;                       // kg·m² about the centre of mass
  Eigen::Vector3d pose0 = Eigen::Vector3d::Zero();  // (ψ, x, y)
  std::array<bool, 3> free{true, true, true};        // (ψ, x, y)
  int dof() const { return int(free[0]) + int(free[1]) + int(free[2]); }
};

// How a constraint ties two bodies, for engines that model it with their own joints (Bullet):
// point_a on a held on point_b of b along the selected rows of the spatial motion vector
// (planar (ω, x, y), spatial (ωx, ωy, ωz, x, y, z)), world axes.
template <class S>
struct Attachment {
  BodyRef a, b;
  typename S::Pos point_a = S::Pos::Zero(), point_b = S::Pos::Zero();  // body frames
  std::array<bool, S::kDim> rows{};
};

// Choices for the Bullet reference model that the physics does not decide: where to cut loops
// (a tree joint listed here becomes a Bullet constraint, and Bullet's trees are re-grown from the
// world through the rest; the slider crank is 20× more accurate cut at joint 1), solver effort, and
// how a rolling constraint is modelled: NoSlip, the description's own rows as a custom Bullet
// constraint (never slips), or Friction, a sphere collider on a static ground plane with Coulomb
// friction μ (skids when the no-slip force would leave the friction cone).
enum class RollingModel { NoSlip, Friction };
struct BulletHints {
  std::vector<int> cut_joints;
  int solver_iterations = 30;
  RollingModel rolling = RollingModel::NoSlip;
};

template <class S>
struct MechanismKinematics;

// A constraint kind: r rows in the constrained directions only (H̃ applied; eq. (3)'s free motions H
// are what the rows leave out). Each kind lives in its own file that opens with its maths:
//   φ(q) = 0                                 position form (holonomic kinds)
//   J θ' − A v_c = 0                         velocity form: J (r × n tree), A (r × k payload)
//   J θ'' − A α_c + (J'θ' − A'v_c) = 0       acceleration form: the bias J'θ' − A'v_c (+ H̃'-terms)
// and the force: η (r numbers out of the solve) as the spatial force f that body a applies to b.
template <class S>
class Constraint {
 public:
  using Vec = typename S::Vec;
  virtual ~Constraint() = default;
  virtual const char* kind() const = 0;
  virtual int rows() const = 0;
  // False for velocity-level kinds (rolling): no φ, no position projection, Baumgarte without ω²φ.
  virtual bool holonomic() const { return true; }
  // True for one-sided kinds (plane_contact): φ = −gap, J θ' − A v_c = −gap', η ≥ 0 presses. The
  // mechanism closes and opens their rows (a released row carries η = 0 and writes nothing).
  virtual bool unilateral() const { return false; }
  // True when the kind is a force element instead of rows (a compliant contact): its rows stay
  // released and the mechanism applies compliantForce() as η through its J.
  virtual bool compliant() const { return false; }
  virtual double compliantForce(const MechanismKinematics<S>& k) const {
    (void)k;
    return 0.0;
  }
  // Position stage: φ (rows), J (rows × n) and A (rows × k), written at row offset `row` of the
  // mechanism's stacked matrices (which arrive zeroed in those rows).
  virtual void position(const MechanismKinematics<S>& k, int row, VecN& phi, MatN& J, MatN& A) const = 0;
  // Velocity stage: the bias J'θ' − A'v_c of its rows.
  virtual void bias(const MechanismKinematics<S>& k, int row, VecN& b) const = 0;
  // The spatial force (world axes, at the constraint's point) body a applies to body b, from its η.
  virtual Vec force(const MechanismKinematics<S>& k, const double* eta) const = 0;
  // The point where force() applies, world coordinates.
  virtual typename S::Pos point(const MechanismKinematics<S>& k) const = 0;
  // Extra quantities a kind reports (a contact: normal and tangential force, cone margin).
  virtual std::vector<std::string> reportNames() const { return {}; }
  virtual void report(const MechanismKinematics<S>& k, const double* eta, double* out) const {
    (void)k, (void)eta, (void)out;
  }
  // The same tie, for the Bullet builder.
  virtual Attachment<S> attachment() const = 0;
};

template <class S>
using ConstraintPtr = std::shared_ptr<const Constraint<S>>;

// An external force on a body (a push, a disturbance, a spring to the world): data of the description
// like the constraints. The engines evaluate it from the time and the motion of its point at every stage
// of a step (hand: each RK4 stage; Bullet: each of its steps), never hold it over the step as they hold
// the sampled τ. The hand engine applies Q = J_Pᵀ F (J_P the point's Jacobian: addPointJacobian's
// [J, −A]); its power F·V_P joins the work of the books (integrate.h). Kinds: physics/forces.h.
template <class S>
class ExternalForce {
 public:
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;
  virtual ~ExternalForce() = default;
  virtual const char* kind() const = 0;
  // The body it acts on (a link or a payload) and its point there (body frame).
  virtual BodyRef body() const = 0;
  virtual Pos point() const = 0;
  // The spatial force (world axes, at the point: planar (τ, f_x, f_y)) at time t, with the point at p
  // (world) moving with the spatial velocity V of a world-aligned frame there.
  virtual Vec force(double t, const Pos& p, const Vec& V) const = 0;
};

template <class S>
using ExternalForcePtr = std::shared_ptr<const ExternalForce<S>>;

// The description: data only, shared by the hand-written engine and the Bullet builder.
template <class S>
struct MechanismModel {
  TreeModel<S> tree;                       // every tree: a body whose parent is −1 hangs from the world
  std::vector<JointProperties> joints;     // per tree joint (empty: none)
  std::vector<Payload> payloads;           // planar mechanisms only
  std::vector<ConstraintPtr<S>> constraints;
  std::vector<ExternalForcePtr<S>> forces;  // external forces on links and payloads
  BulletHints bullet;

  int treeDof() const { return tree.dof(); }
  int payloadDof() const {
    int k = 0;
    for (const auto& p : payloads) k += p.dof();
    return k;
  }
  int rows() const {
    int r = 0;
    for (const auto& c : constraints) r += c->rows();
    return r;
  }
  // The first coordinate of payload i within x_c (−1 if it has none).
  int payloadOffset(int i) const {
    int k = 0;
    for (int j = 0; j < i; ++j) k += payloads[std::size_t(j)].dof();
    return k;
  }
  // Empty if the description is usable, else what is wrong (one sentence).
  std::string validate() const;
};

// The kinematics of every body at one state, what constraint kinds read: filled by the mechanism in
// a position stage (θ, x_c) and a velocity stage (θ', v_c). Links' velocities and velocity-product
// accelerations are the tree's world-coordinate ones (TreeData v_w, a_w: chain_world.h).
template <class S>
struct MechanismKinematics {
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;
  const MechanismModel<S>* model = nullptr;
  const TreeData<S>* tree = nullptr;
  // Payload poses and velocities (planar: (ψ, x, y) and (ω, vx, vy) of the centre of mass), and
  // (cos ψ, sin ψ) of each pose.
  std::vector<Eigen::Vector3d> payload_pose, payload_rate;
  std::vector<Eigen::Vector2d> payload_cs;
  // Planar: each link's absolute angle (the sum of its path's joint angles and fixed placements).
  std::vector<double> link_angle;
  // The tree's joint coordinates θ (position stage) and rates θ' (velocity stage): what joint-space
  // kinds (joint_limit.h, coupling.h) read.
  VecN theta, theta_rate;

  // World position of a point given in a body's frame (the world's frame is the world).
  Pos position(const BodyRef& b, const Pos& p) const;
  // The body's orientation: planar angle (world: 0).
  double angle(const BodyRef& b) const;
  // Rotation taking body-frame coordinates to world coordinates.
  typename S::Rot rotation(const BodyRef& b) const;
  // A direction given in the body's frame, in world coordinates: rotation(b) d without the matrix.
  Pos direction(const BodyRef& b, const Pos& d) const {
    if (b.kind == BodyRef::Kind::Link) return tree->X_world[std::size_t(b.index)].E.transpose() * d;
    return rotation(b) * d;
  }
  // The velocity of a world-aligned frame at world point p moving with body b: V = Jb θ' + Ab v_c.
  // Adds sign × the rows of V (mask) into J (tree columns) and A (payload columns) at `row`; A gets
  // −sign, so that J θ' − A v_c = sign × V's rows.
  void addPointJacobian(const BodyRef& b, const Pos& p_world, const std::array<bool, S::kDim>& rows,
                        double sign, int row, MatN& J, MatN& A) const;
  // One row along a world direction d: adds sign × d·v(p) (v(p): the linear velocity of b's point at
  // p_world) into J and A at `row` (A with −sign, as above): addPointJacobian's rows combined along d
  // without forming them.
  void addDirectionJacobian(const BodyRef& b, const Pos& p_world, const Pos& d, double sign, int row, MatN& J, MatN& A) const;
  // The classical acceleration at p_world of that frame when θ'' = 0 and α_c = 0: J'θ' − A'v_c's
  // share of body b (velocity stage required).
  // With `velocity`, also that frame's spatial velocity (pointVelocity), computed on the way.
  Vec pointBias(const BodyRef& b, const Pos& p_world, Vec* velocity = nullptr) const;
  // pointBias's linear rows alone (spatial links without the angular rows; the same sums).
  Pos linearBias(const BodyRef& b, const Pos& p_world) const;
  // d · pointBias's linear rows (a classical acceleration's component along world direction d).
  double directionBias(const BodyRef& b, const Pos& p_world, const Pos& d) const;
  // The full spatial velocity of that frame (velocity stage required).
  Vec pointVelocity(const BodyRef& b, const Pos& p_world) const;
};

}  // namespace dyn
