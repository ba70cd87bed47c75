// Direct force control on the closed chain (lecture §3, "Closed-chain force control"):
//   τ = τ_m + τ_f,   τ_f = Jᵀ F,   F = (0, 0, ξ) ∈ N(Aᵀ)  ⇒  α_c untouched, f_Ty = ξ + d
//   motion:  τ_m = G(θ) + Jᵀ A u,   u = k_px (x_d − x_c) + k_dx (ẋ_d − v_c)   (a force on the slider)
//   force laws on the measured f_Ty (delayed by `delay`, at least one step):
//     open loop      ξ = f_des
//     proportional   ξ = f_des − k_pf (f_meas − f_des)          (needs k_pf < 1 under delay)
//     integral       ξ = f_des − k_if ∫ (f_meas − f_des) dt     (robust to the delay)
// The same controller drives both engines; it uses the hand-written model for G and J (the arm
// without its tool: the tool's weight m_t g reaches the rail as a disturbance only feedback removes).
#pragma once
#include <cstdint>
#include <random>
#include <vector>

#include "labs/delay_line.h"
#include "labs/slider_crank/mechanism.h"
#include "physics/det/normal.h"

namespace dyn::slider_crank {

enum class ControllerKind { None, ForceControl };
enum class ForceLaw { OpenLoop, Proportional, Integral };

struct Gains {
  double kp_x = 0, kd_x = 0;  // N/m, N·s/m
  double kp_f = 0, ki_f = 0;  // 1, 1/s
};

struct ControllerConfig {
  ControllerKind kind = ControllerKind::None;
  ForceLaw law = ForceLaw::Integral;
  Gains gains;
  double f_des = 0;        // N, desired f_Ty
  double delay = 0;        // s, force-measurement delay
  double noise_std = 0;    // N, measurement noise (seeded)
  std::uint64_t seed = 1;
};

// x_d(t) = x0 + amplitude (1 − cos(2π t / period)) / 2: starts at rest at x0.
struct Reference {
  double x0 = 0, amplitude = 0, period = 1;
  double position(double t) const;
  double velocity(double t) const;
};

class Controller {
 public:
  Controller(const ControllerConfig& config, const Reference& reference, const Params& model, double dt);
  // Joint torques at time t from the measured state and the delayed force measurement.
  Eigen::Vector3d torque(double t, const Eigen::Vector3d& theta, const Eigen::Vector3d& theta_rate,
                         double x_c, double v_c);
  // Feed the force of the step just taken; it reaches the controller `delay` later.
  void measure(double f_Ty);
  // The sensor has been measuring before t = 0 (the lecture's loop starts from a measured force,
  // not from 0 N): with the force loop at rest (f_meas = f_des), the force the t = 0 torque
  // produces on the real arm (plant) at the initial state (q, v) fills the delay line.
  void primeMeasurement(Mechanism& plant, const VecN& q, const VecN& v);
  double measured() const;  // what the force law currently sees
  const Reference& reference() const { return reference_; }
  const ControllerConfig& config() const { return config_; }

 private:
  ControllerConfig config_;
  Reference reference_;
  Mechanism model_;
  double dt_;
  DelayLine sensor_;  // f_Ty as measured (noise included), `delay` late
  double integral_ = 0;
  std::mt19937_64 rng_;
  det::Normal noise_;  // Marsaglia polar over rng_ (physics/det/normal.h)
};

}  // namespace dyn::slider_crank
