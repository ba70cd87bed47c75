// Object-level grasp control; equations in controller.h.
#include "labs/grasp/controller.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

#include "physics/det/det.h"

namespace dyn::grasp {
namespace {
constexpr double kSwingPeak = 1.299038105676658;  // 3√3/4, the peak of sin u − sin 2u / 2
}

void Reference::at(double t, Eigen::Vector3d& pose, Eigen::Vector3d& rate, Eigen::Vector3d& accel) const {
  pose = pose0;
  rate.setZero();
  accel.setZero();
  // Lift: y = y0 + lift · s(τ), s = 10τ³ − 15τ⁴ + 6τ⁵.
  const double tau = std::clamp(t / lift_time, 0.0, 1.0);
  const bool lifting = t > 0 && t < lift_time;
  pose[2] += lift * tau * tau * tau * (10 - 15 * tau + 6 * tau * tau);
  if (lifting) {
    rate[2] = lift * 30 * tau * tau * (1 - tau) * (1 - tau) / lift_time;
    accel[2] = lift * 60 * tau * (1 - 3 * tau + 2 * tau * tau) / (lift_time * lift_time);
  }
  // Sideways swing with tilt over one period after the hold.
  const double t1 = lift_time + hold;
  if (t > t1 && t < t1 + period) {
    const double w = 2 * M_PI / period, u = w * (t - t1);
    const double g = (det::sin(u) - 0.5 * det::sin(2 * u)) / kSwingPeak;
    const double gd = w * (det::cos(u) - det::cos(2 * u)) / kSwingPeak;
    const double gdd = w * w * (-det::sin(u) + 2 * det::sin(2 * u)) / kSwingPeak;
    pose[0] += tilt * g, rate[0] = tilt * gd, accel[0] = tilt * gdd;
    pose[1] += sideways * g, rate[1] = sideways * gd, accel[1] = sideways * gdd;
  }
}

Controller::Controller(const ControllerConfig& c, const Reference& r, const Params& model, double dt)
    : config_(c), reference_(r), model_(model), dt_(dt), sensor_(c.delay, dt, c.gains.f_squeeze), need_(c.delay, dt, 0.0),
      squeeze_(c.gains.f_squeeze), rng_(c.seed) {}

void Controller::primeMeasurement(Mechanism& plant, const VecN& q, const VecN& v) {
  // The contact forces the t = 0 torques produce in the plant.
  auto forces = [&] {
    const auto sol = plant.solve(q, v, torque(0.0, q, v));
    VecN F(2 * plant.fingers());
    for (int i = 0; i < plant.fingers(); ++i) F.segment<2>(2 * i) = plant.constraintForce(i, sol).tail<2>();
    return F;
  };
  sensor_.fill(config_.gains.f_squeeze);
  need_.fill(0.0);
  integral_ = 0;
  // The grasp has been holding the object before t = 0: the integral already carries the cone's need
  // (the squeeze moves no tangential force, so one pass finds it).
  const Gains& g = config_.gains;
  if (g.ki_int > 0 && g.k_cone > 0) integral_ = g.k_cone * coneNeed(q.tail(3), forces()) / g.ki_int;
  const VecN F = forces();
  sensor_.fill(model_.internalForce(q.tail(3), F));
  tangent_ = tangential(q.tail(3), F);
  need_.fill(coneNeed(q.tail(3), F));
}

VecN Controller::tangential(const Eigen::Vector3d& pose, const VecN& F) const {
  VecN ft(model_.fingers());
  for (int i = 0; i < model_.fingers(); ++i) {
    const Eigen::Vector2d n = model_.contactNormal(i, pose[0]);
    ft[i] = F.segment<2>(2 * i).dot(Eigen::Vector2d(-n.y(), n.x()));
  }
  return ft;
}

double Controller::coneNeed(const Eigen::Vector3d& pose, const VecN& F) const {
  return tangential(pose, F).cwiseAbs().maxCoeff() / model_.params().mu;
}

void Controller::measure(const VecN& q, const VecN& F) {
  VecN Fm = F;
  if (config_.noise_std > 0)
    for (Eigen::Index i = 0; i < Fm.size(); ++i) Fm[i] += config_.noise_std * noise_(rng_);
  sensor_.push(model_.internalForce(q.tail(3), Fm));
  // f̄_t' = (f_t,meas − f̄_t) / T_f, then the cone's need from the filtered forces.
  tangent_ += dt_ / (kTangentFilter + dt_) * (tangential(q.tail(3), Fm) - tangent_);
  need_.push(tangent_.cwiseAbs().maxCoeff() / model_.params().mu);
  // The squeeze law integrates what it sees.
  integral_ += (setPoint() - measured()) * dt_;
}

double Controller::measured() const { return sensor_.value(); }

double Controller::setPoint() const { return config_.gains.f_squeeze + config_.gains.k_cone * need_.value(); }

double Controller::setPointFor(const Eigen::Vector3d& pose, const VecN& F) const {
  return config_.gains.f_squeeze + config_.gains.k_cone * coneNeed(pose, F);
}

VecN Controller::torque(double t, const VecN& q, const VecN& v) {
  const int n = model_.n();
  if (config_.kind == ControllerKind::None) return VecN::Zero(n);
  if (config_.kind == ControllerKind::Constant) return Eigen::Map<const Eigen::VectorXd>(config_.torques.data(), n);
  const Gains& g = config_.gains;
  const Params& p = model_.params();
  Eigen::Vector3d pose_d, rate_d, accel_d;
  reference_.at(t, pose_d, rate_d, accel_d);
  const Eigen::Vector3d pose = q.tail(3), rate = v.tail(3);
  // The wrench that moves the object: feed-forward, PD on the pose, its weight.
  const Eigen::Vector3d Mc(p.object.inertia, p.object.mass, p.object.mass);
  const Eigen::Vector3d kp(g.kp_psi, g.kp_pos, g.kp_pos), kd(g.kd_psi, g.kd_pos, g.kd_pos);
  Eigen::Vector3d W = Mc.cwiseProduct(accel_d) + kp.cwiseProduct(pose_d - pose) + kd.cwiseProduct(rate_d - rate);
  W.tail<2>() -= p.object.mass * p.gravity;
  // Contact forces: the least-norm share of W, plus the squeeze along N(G).
  MatN G;
  VecN d;
  model_.graspMap(pose, G, d);
  const Eigen::Matrix3d GGt = G * G.transpose();
  squeeze_ = g.f_squeeze + g.ki_int * integral_;  // the integral carries f_d's rise above f_sq
  const VecN F = G.transpose() * GGt.ldlt().solve(W) + squeeze_ * d;
  // Torques: each finger holds its own weight and pushes its share through Jᵀ.
  return model_.gravityTorque(q) + model_.tipJacobian(q).transpose() * F;
}

}  // namespace dyn::grasp
