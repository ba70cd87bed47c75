// The unicycle's controller; the laws are in controller.h.
#include "labs/unicycle/controller.h"

#include <cmath>

#include "physics/det/det.h"

namespace dyn::unicycle {

Controller::Controller(const ControllerConfig& config, const Path& path, const ReferenceSettings& reference, double radius, double dt)
    : config_(config), leader_(path, reference, config.gains.a_lat), radius_(radius), dt_(dt),
      drive_(config.delay, dt), steer_(config.delay, dt), rng_(config.seed) {}

VecN Controller::torque(double t, const VecN& q, const VecN& v) {
  (void)t;
  // The leader's point and the wheel's cross-track error from it.
  const Path::Sample ref = leader_.sample();
  const Eigen::Vector2d n_d(-det::sin(ref.heading), det::cos(ref.heading));
  target_ = {ref.p, ref.heading, ref.curvature * leader_.speed(), leader_.speed(), (Eigen::Vector2d(q[X], q[Y]) - ref.p).dot(n_d), leader_.s()};
  measured_ = v[Theta] + (config_.speed_noise > 0 ? config_.speed_noise * noise_(rng_) : 0.0);
  double tau_y = 0, tau_z = 0;
  switch (config_.kind) {
    case ControllerKind::None: break;
    case ControllerKind::Constant:
      tau_y = config_.tau_drive;
      tau_z = config_.tau_steer;
      break;
    case ControllerKind::Path: {
      const Gains& g = config_.gains;
      const double e_v = target_.speed / radius_ - measured_;
      integral_ += e_v * dt_;
      tau_y = g.kp_speed * e_v + g.ki_speed * integral_;
      const double heading_c = target_.heading - det::atan(g.k_cross * target_.cross_track);
      tau_z = g.kp_heading * std::remainder(heading_c - q[Phi], 2 * M_PI) + g.kd_heading * (target_.heading_rate - v[Phi]);
      break;
    }
  }
  leader_.advance(dt_);
  // The actuators: `delay` late (the line holds at least one step, so no delay bypasses it).
  if (config_.delay > 0) {
    drive_.push(tau_y);
    steer_.push(tau_z);
    tau_y = drive_.value();
    tau_z = steer_.value();
  }
  VecN tau = VecN::Zero(5);
  tau[Phi] = tau_z;
  tau[Theta] = tau_y;
  return tau;
}

}  // namespace dyn::unicycle
