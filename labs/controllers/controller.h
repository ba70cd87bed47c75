// The controller library of data-defined labs (labs/generic): the lecture's laws on any closed chain
// or open tree from a model file, in its actuated coordinates u (physics/closed_chain.h: S, M_u = SᵀMS,
// h_u, G_u, J_x, Λ; an open chain has S = I). e = x_d − x is the task error, e_u = u_d − u the joint one:
//   none                   τ_u = 0
//   constant               τ_u = the "constant" torques
//   joint_pd_gravity       τ_u = K_p e_u + K_d e_u' + G_u(u)                          (kp, kd)
//   pid                    τ_u = K_p e_u + K_d e_u' + u_I, u_I' = K_i e_u, with anti-windup (kp, ki, kd)
//   computed_torque        τ_u = M_u (u_d'' + K_d e_u' + K_p e_u) + h_u               (omega_n, zeta)
//   task_pd_gravity        τ_u = J_xᵀ (K_p e + K_d e') + G_u                          (kp, kd)
//   task_inverse_dynamics  τ_u = M_u J_x⁻¹ (x_d'' + K_d e' + K_p e − J_x' u') + h_u   (omega_n, zeta)
// The target impedance M ẍ̃ + D ẋ̃ + K x̃ = F_ext (x̃ = x − x_d, lecture §4), F_ext the environment's force
// on the tool as a force sensor reads it (Reference::force), realised two ways:
//   impedance_task         τ_u = J_xᵀ (K e + D e') + G_u + τ_N                         (k_imp, d_imp)
//                          no force sensing: the tool keeps the arm's own Λ(u) as its mass
//   impedance_inverse_dynamics   ẍ* = x_d'' + M⁻¹(F − D x̃' − K x̃)  (laws::impedanceAcceleration),
//                          τ_u = M_u J̄ (ẍ* − J_x' u') + h_u − J_xᵀ F + τ_N
//                              = J_xᵀ (Λ (ẍ* − J_x' u') − F) + h_u + τ_N              (k_imp, d_imp, m_imp)
//                          with force feedback: the tool's mass is M whatever Λ (exact model: x'' = ẍ*)
//   impedance_joint        the target driven by the measured force gives x_d* (ξ'' of the line above,
//                          semi-implicit Euler over the control period), inverse kinematics u_d*, and
//                          computed torque tracks it: τ_u = M_u (u_d*'' + K_d e_u' + K_p e_u) + h_u,
//                          u_d*' = J_x⁺ x_d*', u_d*'' = J_x⁺(x_d*'' − J_x' u_d*') (minimum-norm)
//                                                                          (k_imp, d_imp, m_imp, omega_n, zeta)
//                          the joint loop's compliance sits in series with the target: it realises it
//                          only as far as ω_n is fast against √(K/M)
// J̄ = M_u⁻¹ J_xᵀ Λ is the dynamically consistent inverse of J_x (Λ = (J_x M_u⁻¹ J_xᵀ)⁻¹); with more
// actuated joints than task axes (a 6-joint arm, a 3-axis tool position) the rest is the null space,
// held by a posture term that accelerates nothing along the task:
//   τ_N = Nᵀ M_u (ω_0² (u_0 − u) − 2ω_0 u'),  Nᵀ = I − J_xᵀ J̄ᵀ  (J_x M_u⁻¹ Nᵀ = 0; so u'' gains N a_0)
// u_0 the start pose, ω_0 the controller's "posture_omega" (0: no posture term; critically damped).
// with K_p = ω_n², K_d = 2ζω_n where named so; the arithmetic is laws.h's, shared with the C++ labs. The
// joint laws' gains are scaled per joint by joint_scale (computed torque's are not: they set the error
// dynamics), and pid may add Coulomb compensation F̂_c sat(u_d'/w) from the model's joint friction. Joint laws track the task path through inverse kinematics
// on the controller's model (u_d, u_d' = J_x⁻¹ x_d', u_d'' = J_x⁻¹ (x_d'' − J_x' u_d')), or follow a joint
// path directly (Reference::joint: u_d, u_d', u_d'' given, no inverse kinematics). The controller
// samples at its period (zero-order hold), reads encoders on every joint `delay` steps late with seeded
// Gaussian noise, knows only its own model (a payload the plant carries may be missing from it), and
// saturates at the torque limits.
#pragma once
#include <cstdint>
#include <deque>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "labs/controllers/laws.h"
#include "physics/closed_chain.h"
#include "physics/constrained_mechanism.h"
#include "physics/det/normal.h"

namespace dyn::controllers {

enum class Kind {
  None,
  Constant,
  JointPdGravity,
  Pid,
  ComputedTorque,
  TaskPdGravity,
  TaskInverseDynamics,
  ImpedanceTask,
  ImpedanceInverseDynamics,
  ImpedanceJoint
};
// The kinds by name, as a lab JSON writes them, and the gains each reads.
const std::vector<std::string>& kindNames();
Kind kindFromName(const std::string& name);
std::vector<std::string> gainsOf(Kind kind);

struct Spec {
  Kind kind = Kind::None;
  double period = 1e-3;        // s, a whole number of steps
  long delay_steps = 0;        // encoders read this many steps late
  double noise_angle = 0, noise_rate = 0;  // rad, rad/s (m, m/s on a slide): standard deviations
  double noise_force = 0;                  // N: the force sensor's (impedance laws)
  std::uint64_t seed = 1;
  VecN constant;               // per actuated joint
  VecN torque_limit;           // per actuated joint (> 0)
  double kp = 0, kd = 0, ki = 0, omega_n = 0, zeta = 0;
  double k_imp = 0, d_imp = 0, m_imp = 1;  // the impedance laws' K (N/m), D (N·s/m), M (kg) per task axis
  double posture_omega = 0;                // rad/s: the impedance laws' null-space posture term (0: none)
  VecN joint_scale;             // per actuated joint (empty: all 1) for joint_pd_gravity and pid
  laws::AntiWindup anti_windup = laws::AntiWindup::Clamping;  // pid's integral
  double tracking_time = 0.05;  // s, back-calculation's T_t
  bool coulomb_compensation = false;  // pid: add F̂_c sat(u_d'/w), F̂_c the model's Coulomb friction
  double compensation_width = 0.05;   // rad/s: w
};

// Where the task is: a point of a tree body (its frame), and the rows of its spatial velocity that the
// task uses (3, 4, 5: x, y, z).
struct TaskPoint {
  int link = -1;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  std::vector<int> axes;
};

// The reference at one instant, in the task's axes (joint: in the actuated coordinates, u_d, u_d', u_d'').
struct Reference {
  VecN x, xd, xdd;
  bool joint = false;
  VecN force = VecN();  // the environment's force on the tool in the task axes (N), what a sensor reads (empty: 0)
};

// Newton on (φ(θ), x(θ) − x_d) = 0 over every tree coordinate, minimum-norm steps, from q (the last
// solution): true when every residual is below 1e-12 within 30 steps; q is left at the last iterate
// (the nearest the tool gets, for a point out of reach). The controller's inverse kinematics, and the
// data labs' reach check of a task path (labs/generic/reach.h).
bool inverseKinematics(ConstrainedMechanism<Spatial>& mech, const TaskPoint& task, const VecN& x_d, VecN& q);

class Controller {
 public:
  using Mech = ConstrainedMechanism<Spatial>;
  // model: the controller's own description; actuated: tree coordinates it drives; q0: an assembled
  // pose to start the inverse kinematics from.
  Controller(const Spec& spec, const MechanismModel<Spatial>& model, std::vector<int> actuated, TaskPoint task,
             const VecN& q0, double dt);
  // τ for the whole tree (zeros on passive joints) at step time t from the plant's state.
  VecN torque(double t, const VecN& q, const VecN& v, const Reference& ref);
  // The last command per actuated joint (after saturation), and whether a limit bound.
  const VecN& command() const { return tau_u_; }
  bool saturated() const { return saturated_; }
  const VecN& integral() const { return integral_; }  // pid's u_I per actuated joint (N·m)
  // The task point of the plant's state, by the controller's model (what the trace shows as x).
  void taskPosition(const VecN& q, VecN& x);

 private:
  VecN law(const VecN& q, const VecN& v, const Reference& ref, const VecN& force);
  VecN impedance(const MatN& Jx, const VecN& bias, const VecN& x, const VecN& xdot, const VecN& u, const VecN& w,
                 const Reference& ref, const VecN& force);
  bool inverseKinematics(const VecN& x, VecN& q);
  bool jointMotion(const VecN& x, const VecN& xd, const VecN& xdd, bool min_norm, VecN& ud, VecN& ud_d, VecN& udd_d);

  Spec spec_;
  std::unique_ptr<Mech> mech_;
  ClosedChain<Mech> chain_;
  TaskPoint task_;
  long hold_, k_ = 0;
  double dt_;
  struct Reading {
    VecN q, v, force;
  };
  std::deque<Reading> readings_;  // (q, v, the sensed force) of the last delay+1 steps, newest last
  std::mt19937_64 rng_;
  det::Normal normal_;  // Marsaglia polar over rng_ (physics/det/normal.h)
  VecN q_ik_, integral_, e_u_, tau_u_, tau_;  // integral_: pid's u_I (N·m); e_u_: the last joint error
  VecN u0_;                                     // the actuated coordinates at the start (the posture)
  VecN x_des_, v_des_;                          // impedance_joint: the impedance model's state
  bool saturated_ = false;
};

}  // namespace dyn::controllers
