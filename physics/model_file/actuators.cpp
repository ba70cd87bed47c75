// A model file's actuators in the hand engine: see actuators.h.
#include "physics/model_file/actuators.h"

#include <algorithm>
#include <complex>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cstdio>

#include "physics/model_file/number_text.h"

namespace dyn::model_file {

VecN actuatorTorques(const std::vector<Actuator>& actuators, const VecN& ctrl, const VecN& q, const VecN& v) {
  VecN tau = VecN::Zero(v.size());  // one per rate (a ball's quaternion has one more coordinate)
  for (std::size_t i = 0; i < actuators.size(); ++i) {
    const Actuator& a = actuators[i];
    double u = ctrl[Eigen::Index(i)];
    if (a.ctrl_limited) u = std::clamp(u, a.ctrl_lower, a.ctrl_upper);
    const double length = a.gear * q[a.qpos], rate = a.gear * v[a.coordinate];
    double force = a.gain * u + a.bias[0] + a.bias[1] * length + a.bias[2] * rate;
    if (a.force_limited) force = std::clamp(force, a.force_lower, a.force_upper);
    tau[a.coordinate] += a.gear * force;
  }
  return tau;
}

namespace {

// The engine with the actuators' torques added to τ wherever the integrator evaluates it.
class Actuated final : public ConstrainedSystem {
 public:
  Actuated(std::unique_ptr<ConstrainedSystem> inner, std::vector<Actuator> actuators, VecN ctrl)
      : inner_(std::move(inner)), actuators_(std::move(actuators)), ctrl_(std::move(ctrl)) {}
  void setTime(double t) override {
    ConstrainedSystem::setTime(t);
    inner_->setTime(t);
  }
  void derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a, double& work, double& friction) override {
    inner_->derivatives(q, v, tau + actuatorTorques(actuators_, ctrl_, q, v), stab, a, work, friction);
  }
  int nq() const override { return inner_->nq(); }
  int nv() const override { return inner_->nv(); }
  void configurationRate(const VecN& q, const VecN& v, VecN& qdot) override { inner_->configurationRate(q, v, qdot); }
  void integrateConfiguration(VecN& q, const VecN& dx, double h) override { inner_->integrateConfiguration(q, dx, h); }
  void normalizeConfiguration(VecN& q) override { inner_->normalizeConfiguration(q); }
  void accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a) override {
    inner_->accelerations(q, v, tau + actuatorTorques(actuators_, ctrl_, q, v), stab, a);
  }
  void constraint(const VecN& q, VecN& phi, MatN& G) override { inner_->constraint(q, phi, G); }
  void baumgarteTerm(const VecN& q, const VecN& v, double zeta, double omega, VecN& s) override { inner_->baumgarteTerm(q, v, zeta, omega, s); }
  void metric(const VecN& q, MatN& W) override { inner_->metric(q, W); }
  bool correction(const VecN& q, const VecN& e, VecN& dx) override { return inner_->correction(q, e, dx); }
  bool recoverDependent(VecN& q, VecN& v) override { return inner_->recoverDependent(q, v); }

 private:
  std::unique_ptr<ConstrainedSystem> inner_;
  std::vector<Actuator> actuators_;
  VecN ctrl_;
};

std::string number(double x) { return detail::numberText(x, 6); }

}  // namespace

std::unique_ptr<ConstrainedSystem> withActuators(std::unique_ptr<ConstrainedSystem> engine, const LoadedModel& m) {
  if (m.actuators.empty()) return engine;
  return std::make_unique<Actuated>(std::move(engine), m.actuators, m.ctrl);
}

namespace {

// RK4 follows x' = λ x at step h while |R(λ h)| ≤ 1.
bool rk4Follows(std::complex<double> z) { return std::abs(1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0) <= 1.0 + 1e-12; }

bool followsAt(const Eigen::VectorXcd& modes, double h) {
  for (Eigen::Index i = 0; i < modes.size(); ++i)
    if (!rk4Follows(modes[i] * h)) return false;
  return true;
}

}  // namespace

std::string stiffServoNote(const LoadedModel& m, const MatN& M, double dt) {
  const Eigen::Index n = M.rows();
  VecN k = VecN::Zero(n), c = VecN::Zero(n);
  for (const Actuator& a : m.actuators) {
    k[a.coordinate] -= a.gear * a.gear * a.bias[1];
    c[a.coordinate] -= a.gear * a.gear * a.bias[2];
  }
  if (n == 0 || (k.maxCoeff() <= 0 && c.maxCoeff() <= 0)) return "";
  // x = (q, v): x' = [0 1; −M⁻¹K −M⁻¹C] x.
  const Eigen::MatrixXd Minv = Eigen::MatrixXd(M).inverse();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -Minv * k.asDiagonal();
  A.bottomRightCorner(n, n) = -Minv * c.asDiagonal();
  const Eigen::VectorXcd modes = Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues();
  if (!modes.allFinite() || followsAt(modes, dt)) return "";
  double h = dt;
  for (int halvings = 0; halvings < 60 && !followsAt(modes, h); ++halvings) h /= 2;
  return "the servos (stiffness up to " + number(k.maxCoeff()) + ", damping up to " + number(c.maxCoeff()) + ", fastest mode " +
         number(modes.cwiseAbs().maxCoeff()) + " 1/s at the start) are stiffer than RK4 follows at dt " + number(dt) +
         " s: the run chatters; pass --dt " + number(h) + " or less (MuJoCo 3's implicit integrators take these terms implicitly)";
}

std::string describeControls(const LoadedModel& m) {
  if (m.actuators.empty()) return "";
  std::string names, values;
  for (std::size_t i = 0; i < m.actuators.size(); ++i) {
    names += (i ? ", " : "") + m.actuators[i].name;
    values += (i ? ", " : "") + number(m.ctrl[Eigen::Index(i)]);
  }
  return std::to_string(m.actuators.size()) + (m.actuators.size() == 1 ? " actuator (" : " actuators (") + names + ") at ctrl (" + values + ")";
}

}  // namespace dyn::model_file
