// Position accommodation (lecture §3 "Pen on table", §4 "Impedance control"): an inner task-space
// position loop on the pen tip p, and an outer force law that moves its commanded height z_des.
//   reference  in the table plane p_d = p_c + r (cos ψ, sin ψ); ψ = 0 until t_s, then its rate ramps
//              smoothly (3u² − 2u³, u = (t − t_s)/T_r) up to ω = 2π f: no step in the tip's velocity
//   inner      pd_gravity:        τ = Jᵀ F + G(θ)
//              inverse_dynamics:  τ = Jᵀ (Λ (a_d − J'θ') + F) + C θ' + G(θ)     (Λ = (J M⁻¹ Jᵀ)⁻¹)
//              F = k_p (p_des − p) + k_v (v_des − v),  p_des = (x_d, y_d, z_des), v_des = (ẋ_d, ẏ_d, 0),
//              a_d = (ẍ_d, ÿ_d, 0): the lecture's F_z = −k_p (z − z_des) − k_v ż. Three joints place the
//              tip only: its orientation R_des cannot be controlled as well (no joint is left for it).
//   outer      damper  ż_des = −(f_meas − f_zd) / D_z        (integral force loop on a rigid table)
//              spring  z_des = z_ref − (f_meas − f_zd) / K_z  (proportional), z_ref placed where the
//                      position loop alone presses f_zd on the table it expects: z_t,assumed + f_zd / k_p,
//                      reached from the start height at the approach speed
//   sensor     f_meas: f_z (the force the pen applies to the table, −η: negative pressing) `delay` late
//              (at least one step), plus seeded Gaussian noise
// Off the table f_z = 0, so the damper's z_des descends at |f_zd| / D_z until the pen touches.
// Kinds `none` (τ = 0) and `constant` (τ from the JSON) check the mechanism alone. The controller's
// model (G, J, Λ) is the arm without the pen's extra load, and the table where it expects it.
#pragma once
#include <cstdint>
#include <random>

#include "labs/delay_line.h"
#include "labs/pen_on_table/mechanism.h"
#include "physics/det/normal.h"

namespace dyn::pen_on_table {

enum class ControllerKind { None, Constant, Accommodation };
enum class ForceLaw { Damper, Spring };
enum class InnerLoop { PdGravity, InverseDynamics };

struct Gains {
  double kp = 0, kv = 0;   // N/m, N·s/m: the tip's position loop, every axis
  double D_z = 1, K_z = 1; // N·s/m, N/m: the damper's and the spring's constants
};

// The circle in the table plane, and when it starts.
struct Circle {
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();  // m, p_c
  double radius = 0.08;                              // m
  double frequency = 0.25;                           // Hz
  double start = 1.0, ramp = 0.5;                    // s: t_s, T_r
  // ψ, ψ', ψ'' at t.
  void angle(double t, double& psi, double& rate, double& accel) const;
  // p_d, its velocity and acceleration (table plane) at t.
  void sample(double t, Eigen::Vector2d& p, Eigen::Vector2d& v, Eigen::Vector2d& a) const;
};

struct ControllerConfig {
  ControllerKind kind = ControllerKind::None;
  ForceLaw law = ForceLaw::Damper;
  InnerLoop inner = InnerLoop::PdGravity;
  Gains gains;
  double f_zd = -5;                // N, the set point (negative: pressing)
  double delay = 0.01;             // s, force-measurement delay
  double noise = 0;                // N rms, force-sensor noise
  std::uint64_t seed = 1;
  double table_assumed = 0.1;      // m, where the controller expects the table (the spring's z_ref)
  double approach_speed = 0.05;    // m/s, the spring's z_ref descent
  Eigen::Vector3d torques = Eigen::Vector3d::Zero();  // N·m, constant kind
};

// What the controller aimed at, at one step.
struct Target {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();  // (x_d, y_d, z_des)
  double f_meas = 0;                            // N, the force the outer law saw
};

class Controller {
 public:
  // model: the arm the controller believes in; z0: the tip's height at t = 0 (z_des starts there).
  Controller(const ControllerConfig& config, const Circle& circle, const Params& model, double dt, double z0);
  // Joint torques at t from the state (one call per step, in order).
  VecN torque(double t, const VecN& q, const VecN& v);
  // The force f_z of the step just taken (it reaches the outer law `delay` later).
  void measure(double f_z);
  const Target& target() const { return target_; }
  const ControllerConfig& config() const { return config_; }

 private:
  ControllerConfig config_;
  Circle circle_;
  Mechanism model_;
  double dt_, z0_, z_des_;
  DelayLine sensor_;
  Target target_;
  std::mt19937_64 rng_;
  det::Normal noise_;  // Marsaglia polar over rng_ (physics/det/normal.h)
};

}  // namespace dyn::pen_on_table
