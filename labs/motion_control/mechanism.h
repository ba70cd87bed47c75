// Motion-control arm (lecture §1, §4) described as data: an n-link planar arm in the vertical plane,
// a tree of revolute joints with viscous and Coulomb friction (JointProperties), a payload at the tip.
// Rigid:     q = (θ1 … θn), θi the angle of link i relative to link i−1 (relative joint angles).
// Flexible:  each joint is a rotor (inertia J_r, revolute on link i−1, coaxial with joint i) followed
//            by link i on a revolute joint relative to the rotor whose spring (stiffness k_i, rest 0)
//            is the joint's flexibility: q = (θm1, δ1, θm2, δ2, …), θmi the motor angle relative to
//            link i−1, δi the spring's deflection, link i's relative angle θi = θmi + δi. The motor
//            torque acts on the rotor and reacts on link i−1; friction sits on the motor side.
//            Σ k_i δ_i²/2 is the lecture's ½(θ_m − θ)ᵀK(θ_m − θ) with its tridiagonal K once written
//            in absolute angles (K couples neighbours there; in relative angles it is diagonal).
// No constraints: the generic mechanism with 0 rows. Fixed sizes for the default 3 links.
#pragma once
#include <array>
#include <memory>
#include <vector>

#include "physics/constrained_mechanism.h"
#include "physics/friction_band.h"

namespace dyn::motion_control {

struct Link {
  double length, mass, inertia;  // m, kg, kg·m² about the centre of mass
  Eigen::Vector2d com;           // centre of mass in the link frame (x along the link)
};

struct JointFriction {
  double viscous = 0, coulomb = 0;  // N·m·s/rad, N·m
};

struct Params {
  std::vector<Link> links;
  std::vector<JointFriction> friction;   // per joint
  double coulomb_width = 0.01;           // rad/s, the Coulomb term's smoothing width
  double payload = 0;                    // kg, a point mass at the tip of the last link
  Eigen::Vector2d gravity{0.0, -9.81};
  bool flexible = false;
  std::vector<double> stiffness;         // N·m/rad per joint (flexible)
  double rotor_inertia = 0.01;           // kg·m², each rotor (flexible)
  double rotor_mass = 0.2;               // kg, each rotor (flexible; sits on the joint axis)
  int n() const { return int(links.size()); }
};

using ArmMechanism = ConstrainedMechanism<Planar>;

// The description both engines are built from.
MechanismModel<Planar> describe(const Params& params);
// The rigid arm the controller believes in (no rotors, no springs): same links, its own payload and friction.
MechanismModel<Planar> describeRigid(const Params& params);

// The hand engine's mechanism at the right sizes: fixed for 3 links (rigid 3, flexible 6 joints), else bounded.
template <int Nj>
using FixedArm = ConstrainedMechanism<Planar, Nj, 0, 0>;

// Where the lab's hand engine refines an RK4 step (integrate.h ConstrainedSystem::refine: the step
// retaken from its start in StepOptions::refine_substeps sub-steps, decided by the step's start alone):
// a joint's Coulomb friction near its turn (physics/friction_band.h: |θ'| < kFrictionBandWidths·w +
// 2|θ''|h), and, where a lab sets `swing`, a joint faster than `swing` rad/s (a passive arm whipping
// under gravity: the impedance lab's pushed arm). Both thresholds are rates, not per-step amounts, so the
// steps refined are about the same at any dt and the run converges at RK4's fourth order.
inline constexpr double kFrictionBandWidths = 5;
inline constexpr int kFrictionSubsteps = 4;

// The arm as a lab's hand engine steps it: the mechanism M (FixedArm<N>, ArmMechanism, …), refined there.
template <class M>
class RefinedArm final : public M {
 public:
  using M::M;
  double swing = 0;  // rad/s; 0: no refinement for speed
  bool refine(const VecN& q, const VecN& v, const VecN& a, double h) override {
    (void)q;
    if (nearFrictionTurn(this->model().joints, v, a, h, kFrictionBandWidths)) return true;
    return swing > 0 && v.head(this->n()).cwiseAbs().maxCoeff() > swing;
  }
};

// Map between the tree's coordinates and the arm's (link-side angles, motor-side angles).
struct ArmState {
  Eigen::VectorXd link, link_rate;    // θ, θ' (relative)
  Eigen::VectorXd motor, motor_rate;  // θm, θm' (flexible; = θ rigid)
  Eigen::VectorXd deflection;         // δ = θ − θm
};
ArmState armState(const Params& p, const VecN& q, const VecN& v);
// Tree coordinates from link angles at rest (flexible: the static deflection given).
void treeState(const Params& p, const Eigen::VectorXd& theta, const Eigen::VectorXd& deflection, VecN& q, VecN& v);
// Motor torques (n) into tree torques (n or 2n).
VecN treeTorque(const Params& p, const Eigen::VectorXd& tau);
// Joint points (base, joints 2…n, tip) of the arm at link angles θ.
std::vector<Eigen::Vector2d> jointPoints(const Params& p, const Eigen::VectorXd& theta);

}  // namespace dyn::motion_control
