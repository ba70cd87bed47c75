// The arm's controllers and trajectory; equations in controller.h.
#include "labs/motion_control/controller.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "physics/det/det.h"

namespace dyn::motion_control {
namespace {

// Quintic blend s(u), u ∈ [0, 1], with zero rate and acceleration at both ends, and its derivatives.
void quintic(double u, double& s, double& sd, double& sdd) {
  u = std::clamp(u, 0.0, 1.0);
  s = u * u * u * (10 - 15 * u + 6 * u * u);
  sd = 30 * u * u * (1 - u) * (1 - u);
  sdd = 60 * u * (1 - u) * (1 - 2 * u);
}

}  // namespace

void Trajectory::at(double t, Eigen::VectorXd& q, Eigen::VectorXd& qd, Eigen::VectorXd& qdd) const {
  const Eigen::VectorXd d = folded - outstretched;
  double s = 0, sd = 0, sdd = 0;
  if (t < t2()) {
    quintic(t / move_time, s, sd, sdd);
    q = outstretched + s * d, qd = sd / move_time * d, qdd = sdd / (move_time * move_time) * d;
  } else if (t < t4()) {
    quintic((t - t2()) / move_time, s, sd, sdd);
    q = folded - s * d, qd = -sd / move_time * d, qdd = -sdd / (move_time * move_time) * d;
  } else {
    const double w = 2 * M_PI / period, tau = t - t4();
    q = outstretched + 0.5 * (1 - det::cos(w * tau)) * amplitude;
    qd = 0.5 * w * det::sin(w * tau) * amplitude;
    qdd = 0.5 * w * w * det::cos(w * tau) * amplitude;
  }
}

Controller::Controller(const ControllerConfig& c, const Trajectory& traj, const Params& model)
    : c_(c), traj_(traj), has_traj_(true), model_params_(model),
      model_(std::make_unique<ArmMechanism>(describeRigid(model))), u_i_(Eigen::VectorXd::Zero(model.n())) {}

Controller::Controller(const ControllerConfig& c, const Params& model)
    : c_(c), model_params_(model), model_(std::make_unique<ArmMechanism>(describeRigid(model))),
      u_i_(Eigen::VectorXd::Zero(model.n())) {}

Eigen::VectorXd Controller::torque(double t, const Eigen::VectorXd& th, const Eigen::VectorXd& thd) {
  if (!has_traj_) throw std::logic_error("motion_control::Controller: no trajectory; call torque(t, θ, θ', reference)");
  Reference ref;
  traj_.at(t, ref.q, ref.qd, ref.qdd);
  return torque(t, th, thd, ref);
}

Eigen::VectorXd Controller::torque(double t, const Eigen::VectorXd& th, const Eigen::VectorXd& thd, const Reference& ref) {
  namespace laws = controllers::laws;
  const int n = int(th.size());
  const double dt = last_t_ < 0 ? 0.0 : t - last_t_;
  last_t_ = t;
  // The library's laws (labs/controllers/laws.h) take e = θ_d − θ.
  const Eigen::VectorXd e = ref.q - th, ed = ref.qd - thd;
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(n);
  const auto& fr = model_params_.friction;
  switch (c_.kind) {
    case Kind::None: break;
    case Kind::Constant: tau = c_.constant; break;
    case Kind::Pid:
      tau = laws::pid(c_.kp, e, c_.kd, ed, u_i_);
      if (c_.coulomb_compensation)
        for (int i = 0; i < n; ++i) tau[i] += laws::coulombCompensation(fr[std::size_t(i)].coulomb, ref.qd[i], c_.compensation_width);
      break;
    case Kind::ComputedTorque: {
      const Eigen::VectorXd a = laws::computedTorqueAcceleration(ref.qdd, c_.kp, e, c_.kd, ed);
      tau = model_->inverseDynamics(VecN(th), VecN(thd), VecN(a));
      for (int i = 0; i < n; ++i)
        tau[i] += fr[std::size_t(i)].viscous * thd[i] +
                  fr[std::size_t(i)].coulomb * det::tanh(thd[i] / std::max(model_params_.coulomb_width, 1e-12));
      break;
    }
    case Kind::PdGravity:
      tau = laws::pdGravity(c_.kp, e, c_.kd, Eigen::VectorXd(-thd), Eigen::VectorXd(model_->gravityTorque(VecN(th))));
      break;
  }
  // The plant interface: each joint clipped to ±τ_max; then the integral (anti-windup reads the clip).
  const Eigen::VectorXd raw = tau;
  saturated_ = laws::saturate(tau, c_.tau_max);
  if (c_.kind == Kind::Pid) laws::integrate(u_i_, c_.anti_windup, c_.ki, e, raw, tau, c_.tau_max, c_.tracking_time, dt);
  return tau;
}

double Controller::lyapunov(const Eigen::VectorXd& e, const Eigen::VectorXd& th, const Eigen::VectorXd& thd) {
  const MatN M = model_->massMatrix(VecN(th));
  const Eigen::VectorXd v = thd;
  return 0.5 * v.dot(Eigen::MatrixXd(M) * v) + 0.5 * e.dot(c_.kp.cwiseProduct(e));
}

}  // namespace dyn::motion_control
