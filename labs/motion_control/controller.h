// The three ways to move an arm (lecture §4), on motor-side joint angles θ (relative), e = θ − θ_d:
//   pid              τ_i = −k_P,i e_i − k_I,i ∫e_i − k_D,i e_i' + F̂_c,i sat(θ_d,i'/w)   per joint, with
//                    anti-windup under the torque limit: clamping (the integrator stops while the
//                    output saturates in the direction it pushes) or back-calculation
//                    (u_I' = −k_I e + (τ_sat − τ)/T_t, u_I = −k_I ∫e kept in torque units)
//   computed_torque  τ = M̂(θ)(θ_d'' − K_p e − K_d e') + Ĉθ' + Ĝ + B̂θ' + F̂_c tanh(θ'/w)  (RNEA of the
//                    model at the measured state) ⇒ e'' + K_d e' + K_p e = 0 when the model is exact;
//                    K_p = ω_n², K_d = 2ζω_n (or given directly)
//   pd_gravity       τ = −K_p e − K_d θ' + Ĝ(θ)   (passivity: V = ½θ'ᵀMθ' + ½eᵀK_p e never increases
//                    for a constant θ_d)
//   none, constant   τ = 0, τ = τ_const
// Every τ is clipped to ±τ_max,i (the plant interface); the controller runs every control period
// and its torque is held in between (zero-order hold).
#pragma once
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "labs/controllers/laws.h"
#include "labs/motion_control/mechanism.h"

namespace dyn::motion_control {

enum class Kind { None, Constant, Pid, ComputedTorque, PdGravity };
using AntiWindup = controllers::laws::AntiWindup;  // the library's integral (labs/controllers/laws.h)

// Quintic point-to-point moves outstretched → folded → outstretched (each followed by a hold), then
// a sine about the outstretched pose, θ_d = θ_out + a (1 − cos 2πτ/T)/2 (starts at rest).
struct Trajectory {
  Eigen::VectorXd outstretched, folded, amplitude;
  double move_time = 1, hold_time = 0.5, period = 1;
  // Phase boundaries: move 1 [0, t1), hold folded [t1, t2), move 2 [t2, t3), hold out [t3, t4), sine after.
  double t1() const { return move_time; }
  double t2() const { return move_time + hold_time; }
  double t3() const { return 2 * move_time + hold_time; }
  double t4() const { return 2 * move_time + 2 * hold_time; }
  void at(double t, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const;
};

// The joint reference at one instant: θ_d, θ_d', θ_d'' (the trajectory's, or an outer loop's such as
// the impedance lab's inverse kinematics).
struct Reference {
  Eigen::VectorXd q, qd, qdd;
};

struct ControllerConfig {
  Kind kind = Kind::Pid;
  AntiWindup anti_windup = AntiWindup::Clamping;
  Eigen::VectorXd kp, ki, kd;   // per joint (pid, pd_gravity, computed torque)
  double tracking_time = 0.05;  // s, back-calculation's T_t
  bool coulomb_compensation = true;
  double compensation_width = 0.05;  // rad/s, the compensation's smoothing width w
  Eigen::VectorXd tau_max;      // N·m per joint
  Eigen::VectorXd constant;     // N·m per joint (constant)
  double period = 0.001;        // s, control period (zero-order hold)
};

class Controller {
 public:
  // model: the parameters the controller believes (payload, friction estimate), rigid.
  Controller(const ControllerConfig& c, const Trajectory& traj, const Params& model);
  // Without a trajectory: the reference comes from the caller (the hook below) at every call.
  Controller(const ControllerConfig& c, const Params& model);
  // The saturated torque at time t from motor-side angles and rates, tracking the trajectory;
  // saturated() tells if it clipped.
  Eigen::VectorXd torque(double t, const Eigen::VectorXd& th, const Eigen::VectorXd& thd);
  // The reference hook: the same laws tracking a reference the caller gives (an outer loop).
  Eigen::VectorXd torque(double t, const Eigen::VectorXd& th, const Eigen::VectorXd& thd, const Reference& ref);
  bool saturated() const { return saturated_; }
  // V = ½θ'ᵀM̂θ' + ½eᵀK_p e at the given state (model M̂).
  double lyapunov(const Eigen::VectorXd& e, const Eigen::VectorXd& th, const Eigen::VectorXd& thd);
  const Eigen::VectorXd& integral() const { return u_i_; }  // u_I per joint (N·m)
  const ControllerConfig& config() const { return c_; }

 private:
  ControllerConfig c_;
  Trajectory traj_;
  bool has_traj_ = false;
  Params model_params_;
  std::unique_ptr<ArmMechanism> model_;
  Eigen::VectorXd u_i_;
  double last_t_ = -1;
  bool saturated_ = false;
};

}  // namespace dyn::motion_control
