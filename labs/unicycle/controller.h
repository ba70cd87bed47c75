// The unicycle's path-following controller (lecture §3 "Unicycle": the reduced dynamics decouple,
// (I_a + m r²) θ'' = τ_y, I_z φ'' = τ_z, so one loop per torque):
//   leader     p_d, φ_d, v_d, φ_d' from the path (path.h), cornering at most a_lat
//   errors     e_ct = (p − p_d)·n_d (cross-track, left of the path positive), n_d = (−sin φ_d, cos φ_d)
//   speed      τ_y = k_pv (θ'_d − θ'_m) + k_iv ∫ (θ'_d − θ'_m) dt,  θ'_d = v_d / r   (PI on the spin rate,
//              θ'_m the speed sensor's reading: noisy, seeded)
//   heading    φ_c = φ_d − atan(k_ct e_ct)   (steer back towards the path, at most 90°)
//              τ_z = k_pφ wrap(φ_c − φ) + k_dφ (φ_d' − φ')                     (PD)
//   actuators  the torques arrive `delay` late (0: at once)
// Kinds `none` (τ = 0) and `constant` (τ_y, τ_z from the JSON) check the mechanism alone.
#pragma once
#include <cstdint>
#include <random>

#include "labs/delay_line.h"
#include "labs/unicycle/mechanism.h"
#include "labs/unicycle/path.h"
#include "physics/det/normal.h"

namespace dyn::unicycle {

enum class ControllerKind { None, Constant, Path };

struct Gains {
  double kp_speed = 0, ki_speed = 0;       // N·m·s/rad, N·m/rad
  double kp_heading = 0, kd_heading = 0;   // N·m/rad, N·m·s/rad
  double k_cross = 0;                      // rad/m
  double a_lat = 1;                        // m/s², the leader's cornering limit
};

struct ControllerConfig {
  ControllerKind kind = ControllerKind::None;
  Gains gains;
  double tau_drive = 0, tau_steer = 0;     // constant kind, N·m
  double delay = 0;                        // s, actuation delay
  double speed_noise = 0;                  // rad/s rms on the spin-rate reading
  std::uint64_t seed = 1;
};

// What the controller aims at, at one step.
struct Target {
  Eigen::Vector2d p = Eigen::Vector2d::Zero();
  double heading = 0, heading_rate = 0, speed = 0;  // rad, rad/s, m/s
  double cross_track = 0;                           // m, the wheel's e_ct
  double s = 0;                                     // m, the leader's arc length along the path
};

class Controller {
 public:
  Controller(const ControllerConfig& config, const Path& path, const ReferenceSettings& reference, double radius, double dt);
  // (τ_z, τ_y) as generalised forces on q = (x, y, z, φ, θ), from the state at t (one call per step).
  VecN torque(double t, const VecN& q, const VecN& v);
  const Target& target() const { return target_; }
  double measuredSpeed() const { return measured_; }  // the spin rate the speed loop saw, rad/s

 private:
  ControllerConfig config_;
  Leader leader_;
  double radius_, dt_;
  DelayLine drive_, steer_;
  double integral_ = 0, measured_ = 0;
  Target target_;
  std::mt19937_64 rng_;
  det::Normal noise_;  // Marsaglia polar over rng_ (physics/det/normal.h)
};

}  // namespace dyn::unicycle
