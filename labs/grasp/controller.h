// Object-level grasp control (lecture §3 "Multi-finger grasp" and "Closed-chain force control"):
//   wrench     W = M_c (α_d) + K_p (x_d − x_o) + K_d (v_d − v_o) − M_c g        on (ψ, x, y), world axes
//              K_p = diag(k_pψ, k_p, k_p), K_d = diag(k_dψ, k_d, k_d), M_c = diag(I_o, m_o, m_o)
//   contacts   F = G⁺ W + s d                 (G⁺W moves the object; s d ∈ N(G) = N(Aᵀ) squeezes it)
//   set point  f_d = f_sq + k_c max_i |f̄_t,i| / μ̂           (the friction cone's need, from the measured
//              tangential forces low-passed over kTangentFilter, plus the margin f_sq; k_c = 0: f_d = f_sq)
//   squeeze    s = f_sq + k_if ∫ (f_d − f_int,meas) dt     (f_int,meas, f_t,meas: delayed, noisy contact forces)
//   torques    τ = G(θ) + Jᵀ F                (J: the fingertips' translational Jacobian)
// The controller's model (object mass and inertia, μ̂) is its own: a heavier object or less friction in
// the plant stays unknown to it (the fingers' geometry and weight it knows).
// The fingers' own inertia is not compensated: it is what the motion loops and the squeeze loop see as
// a disturbance (the lecture's "motion-induced force" d of the force loop). Kinds `none` (τ = 0) and
// `constant` (τ from the JSON) check the mechanism alone.
#pragma once
#include <cstdint>
#include <random>
#include <vector>

#include "labs/delay_line.h"
#include "labs/grasp/mechanism.h"
#include "physics/det/normal.h"

namespace dyn::grasp {

// s, the first-order low-pass on the measured tangential forces (noise would otherwise bias max |f_t|).
inline constexpr double kTangentFilter = 0.05;

enum class ControllerKind { None, Constant, Grasp };

struct Gains {
  double kp_pos = 0, kd_pos = 0;   // N/m, N·s/m
  double kp_psi = 0, kd_psi = 0;   // N·m/rad, N·m·s/rad
  double f_squeeze = 0;            // N, the internal-force set point f_sq
  double ki_int = 0;               // 1/s, integral gain on the measured internal force
  double k_cone = 0;               // 1, friction-cone feedback: f_d grows by k_c |f_t,meas| / μ̂
};

struct ControllerConfig {
  ControllerKind kind = ControllerKind::None;
  Gains gains;
  std::vector<double> torques;     // constant kind: one per joint, N·m
  double delay = 0;                // s, contact-force measurement delay (at least one step)
  double noise_std = 0;            // N, per force component (seeded)
  std::uint64_t seed = 1;
};

// The object's reference pose (ψ, x, y): lift by `lift` over `lift_time` (a quintic, at rest at both
// ends), hold, then one period of a sideways swing ±`sideways` with a tilt ±`tilt` that starts and ends
// at rest: g(u) = (sin u − sin 2u / 2) / (3√3/4), u = 2π (t − t_1) / period, |g| ≤ 1.
struct Reference {
  Eigen::Vector3d pose0 = Eigen::Vector3d::Zero();
  double lift = 0.05, lift_time = 1.0, hold = 0.5;   // m, s, s
  double sideways = 0.02, tilt = 0.0, period = 2.0;  // m, rad, s
  // Pose, rate and acceleration at t.
  void at(double t, Eigen::Vector3d& pose, Eigen::Vector3d& rate, Eigen::Vector3d& accel) const;
};

class Controller {
 public:
  Controller(const ControllerConfig& config, const Reference& reference, const Params& model, double dt);
  // Joint torques at t from the measured state (q = (θ, ψ, x, y)).
  VecN torque(double t, const VecN& q, const VecN& v);
  // The contact forces of the step just taken (on the object, world axes, stacked): they reach the
  // squeeze law `delay` later.
  void measure(const VecN& q, const VecN& F);
  // Before t = 0 the sensor has been measuring what the t = 0 torques produce at (q, v) in the plant.
  void primeMeasurement(Mechanism& plant, const VecN& q, const VecN& v);
  double measured() const;         // the internal force the squeeze law currently sees
  double setPoint() const;         // f_d the squeeze law currently aims at (from what it sees)
  // f_d from contact forces F at pose (ψ, x, y), as the law would compute it from a perfect sensor.
  double setPointFor(const Eigen::Vector3d& pose, const VecN& F) const;
  double squeeze() const { return squeeze_; }  // s of the last torque
  const Reference& reference() const { return reference_; }
  const ControllerConfig& config() const { return config_; }

 private:
  double coneNeed(const Eigen::Vector3d& pose, const VecN& F) const;  // max_i |f_t,i| / μ̂
  VecN tangential(const Eigen::Vector3d& pose, const VecN& F) const;   // f_t,i along ẑ × n_i
  ControllerConfig config_;
  Reference reference_;
  Mechanism model_;
  double dt_;
  DelayLine sensor_;               // f_int as measured (from noisy contact forces), `delay` late
  DelayLine need_;                 // max_i |f̄_t,i| / μ̂ as measured, `delay` late
  VecN tangent_;                   // f̄_t,i: each contact's measured tangential force, low-passed
  double integral_ = 0, squeeze_ = 0;
  std::mt19937_64 rng_;
  det::Normal noise_;  // Marsaglia polar over rng_ (physics/det/normal.h)
};

}  // namespace dyn::grasp
