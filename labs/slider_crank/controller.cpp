// Direct force control on the slider crank; equations in controller.h.
#include "labs/slider_crank/controller.h"

#include <algorithm>
#include <cmath>

#include "physics/det/det.h"

namespace dyn::slider_crank {

double Reference::position(double t) const {
  return x0 + 0.5 * amplitude * (1.0 - det::cos(2.0 * M_PI * t / period));
}
double Reference::velocity(double t) const {
  return 0.5 * amplitude * (2.0 * M_PI / period) * det::sin(2.0 * M_PI * t / period);
}

Controller::Controller(const ControllerConfig& c, const Reference& r, const Params& model, double dt)
    : config_(c), reference_(r), model_(model), dt_(dt), sensor_(c.delay, dt), rng_(c.seed) {}

void Controller::primeMeasurement(Mechanism& plant, const VecN& q, const VecN& v) {
  sensor_.fill(config_.f_des);
  const Eigen::Vector3d tau = torque(0.0, q.head(3), v.head(3), q[3], v[3]);
  sensor_.fill(plant.solve(q, v, VecN(tau)).f[2]);
}

void Controller::measure(double f_Ty) {
  sensor_.push(f_Ty + (config_.noise_std > 0 ? config_.noise_std * noise_(rng_) : 0.0));
  // The force loop integrates what it sees.
  integral_ += (measured() - config_.f_des) * dt_;
}

double Controller::measured() const { return sensor_.value(); }

Eigen::Vector3d Controller::torque(double t, const Eigen::Vector3d& th, const Eigen::Vector3d& thd,
                                   double x_c, double v_c) {
  if (config_.kind == ControllerKind::None) return Eigen::Vector3d::Zero();
  const Gains& g = config_.gains;
  // Motion: gravity compensation plus a PD force on the slider along A.
  const double u = g.kp_x * (reference_.position(t) - x_c) + g.kd_x * (reference_.velocity(t) - v_c);
  // Force: ξ on the f_Ty channel, in N(Aᵀ).
  double xi = config_.f_des;
  if (config_.law == ForceLaw::Proportional) xi -= g.kp_f * (measured() - config_.f_des);
  if (config_.law == ForceLaw::Integral) xi -= g.ki_f * integral_;
  MatN J;
  VecN unused;
  model_.tipJacobian(th, thd, J, unused);
  const Eigen::Vector3d F(0.0, u, xi);  // (τ_T, f_x, f_y) at the tip
  return model_.gravityTorque(th) + J.transpose() * F;
}

}  // namespace dyn::slider_crank
