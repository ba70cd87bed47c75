// The pen-on-table controller; the laws are in controller.h.
#include "labs/pen_on_table/controller.h"

#include <algorithm>
#include <cmath>

#include "physics/det/det.h"

namespace dyn::pen_on_table {

void Circle::angle(double t, double& psi, double& rate, double& accel) const {
  const double w = 2 * M_PI * frequency;
  psi = rate = accel = 0;
  if (t <= start) return;
  if (ramp <= 0 || t >= start + ramp) {
    // At full speed: what the ramp turned (ω T_r / 2), then ω per second.
    psi = w * (0.5 * std::max(ramp, 0.0) + (t - start - std::max(ramp, 0.0)));
    rate = w;
    return;
  }
  // The ramp: ψ' = ω (3u² − 2u³), so ψ = ω T_r (u³ − u⁴/2) and ψ'' = ω 6u (1 − u) / T_r.
  const double u = (t - start) / ramp;
  psi = w * ramp * (u * u * u - 0.5 * u * u * u * u);
  rate = w * (3 * u * u - 2 * u * u * u);
  accel = w * 6 * u * (1 - u) / ramp;
}

void Circle::sample(double t, Eigen::Vector2d& p, Eigen::Vector2d& v, Eigen::Vector2d& a) const {
  double psi, rate, accel;
  angle(t, psi, rate, accel);
  const Eigen::Vector2d radial(det::cos(psi), det::sin(psi)), along(-det::sin(psi), det::cos(psi));
  p = centre + radius * radial;
  v = radius * rate * along;
  a = radius * accel * along - radius * rate * rate * radial;
}

Controller::Controller(const ControllerConfig& config, const Circle& circle, const Params& model, double dt, double z0)
    : config_(config), circle_(circle), model_(model), dt_(dt), z0_(z0), z_des_(z0), sensor_(config.delay, dt), rng_(config.seed) {}

void Controller::measure(double f_z) {
  sensor_.push(f_z + (config_.noise > 0 ? config_.noise * noise_(rng_) : 0.0));
}

VecN Controller::torque(double t, const VecN& q, const VecN& v) {
  VecN tau = VecN::Zero(3);
  const Gains& g = config_.gains;
  // The reference in the table plane, and what the force sensor reads now.
  Eigen::Vector2d pd, vd, ad;
  circle_.sample(t, pd, vd, ad);
  const double f_meas = sensor_.value(), e_f = f_meas - config_.f_zd;
  // The outer law: the commanded height.
  double z_des = z_des_;
  if (config_.law == ForceLaw::Spring) {
    const double z_ref = std::max(config_.table_assumed + config_.f_zd / g.kp, z0_ - config_.approach_speed * t);
    z_des = z_ref - e_f / g.K_z;
  }
  target_ = {Eigen::Vector3d(pd.x(), pd.y(), z_des), f_meas};
  switch (config_.kind) {
    case ControllerKind::None: return tau;
    case ControllerKind::Constant: return config_.torques;
    case ControllerKind::Accommodation: break;
  }
  // The damper integrates its height (explicit Euler: z_des of the next step).
  if (config_.law == ForceLaw::Damper) z_des_ -= dt_ * e_f / g.D_z;
  // The inner loop: a task-space PD on the tip, with gravity (and optionally the model's dynamics).
  Eigen::Vector3d p, Jdv;
  Eigen::Matrix3d J;
  model_.tipJacobian(q, v, p, J, Jdv);
  const Eigen::Vector3d v_tip = J * v.head(3);
  const Eigen::Vector3d F = g.kp * (target_.p - p) + g.kv * (Eigen::Vector3d(vd.x(), vd.y(), 0) - v_tip);
  if (config_.inner == InnerLoop::PdGravity) {
    tau = J.transpose() * F + model_.gravityTorque(q);
  } else {
    const MatN Lambda = model_.operationalInertia(q, MatN(J));
    const Eigen::Vector3d a_d(ad.x(), ad.y(), 0);
    const Eigen::Vector3d F_id = Lambda.size() ? Eigen::Vector3d(Eigen::Matrix3d(Lambda) * (a_d - Jdv)) : Eigen::Vector3d::Zero();
    tau = J.transpose() * (F_id + F) + model_.inverseDynamics(q, v, VecN::Zero(3));
  }
  return tau;
}

}  // namespace dyn::pen_on_table
