// A model file's actuators in the hand engine: see actuators.h.
#include "physics/model_file/actuators.h"

#include <algorithm>
#include <complex>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cstdio>

#include "physics/det/det.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file {

namespace {

// Σ coef_k x_k over a path: its length from q (position: each term's coordinate in q) or its rate from v.
double lengthOf(const std::vector<TendonTerm>& path, const VecN& x, bool position = false) {
  double l = 0;
  for (const TendonTerm& t : path) l += t.coef * x[position && t.qpos >= 0 ? t.qpos : t.coordinate];
  return l;
}

void spread(const std::vector<TendonTerm>& path, double force, VecN& tau) {
  for (const TendonTerm& t : path) tau[t.coordinate] += t.coef * force;
}

}  // namespace

VecN actuatorTorques(const std::vector<Actuator>& actuators, const VecN& ctrl, const VecN& q, const VecN& v) {
  VecN tau = VecN::Zero(v.size());  // one per rate (a ball's quaternion has one more coordinate)
  for (std::size_t i = 0; i < actuators.size(); ++i) {
    const Actuator& a = actuators[i];
    double u = ctrl[Eigen::Index(i)];
    if (a.ctrl_limited) u = std::clamp(u, a.ctrl_lower, a.ctrl_upper);
    const double length = a.gear * lengthOf(a.path, q, true), rate = a.gear * lengthOf(a.path, v);
    double force = a.gain * u + a.bias[0] + a.bias[1] * length + a.bias[2] * rate;
    if (a.force_limited) force = std::clamp(force, a.force_lower, a.force_upper);
    spread(a.path, a.gear * force, tau);
  }
  return tau;
}

VecN tendonTorques(const std::vector<TendonSpring>& tendons, const VecN& q, const VecN& v) {
  VecN tau = VecN::Zero(v.size());  // one per rate
  for (const TendonSpring& t : tendons) {
    JointProperties loss;  // the damper and friction as a joint's law (mechanism.h), on the tendon's rate
    loss.viscous = t.damping;
    loss.coulomb = t.frictionloss;
    loss.coulomb_width = t.friction_width;
    spread(t.path, t.stiffness * (t.rest - lengthOf(t.path, q, true)) - loss.friction(lengthOf(t.path, v)), tau);
  }
  return tau;
}

namespace {

// The actuators' torques, and the tendons' when there are some.
VecN drivenBy(const std::vector<Actuator>& actuators, const VecN& ctrl, const std::vector<TendonSpring>& tendons, const VecN& q, const VecN& v) {
  VecN tau = actuatorTorques(actuators, ctrl, q, v);
  if (!tendons.empty()) tau += tendonTorques(tendons, q, v);
  return tau;
}

}  // namespace

VecN Drive::torques(const VecN& q, const VecN& v) const { return drivenBy(actuators, ctrl, tendons, q, v); }

VecN actuatorTorques(const LoadedModel& m, const VecN& q, const VecN& v) { return drivenBy(m.actuators, m.ctrl, m.tendons, q, v); }

namespace {

// The engine with the drive's torques added to τ wherever the integrator evaluates it.
class Actuated final : public ConstrainedSystem {
 public:
  Actuated(std::unique_ptr<ConstrainedSystem> inner, const LoadedModel& m) : inner_(std::move(inner)), drive_(m) {}
  void setTime(double t) override {
    ConstrainedSystem::setTime(t);
    inner_->setTime(t);
  }
  void derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a, double& work, double& friction) override {
    inner_->derivatives(q, v, tau + drive_.torques(q, v), stab, a, work, friction);
  }
  int nq() const override { return inner_->nq(); }
  int nv() const override { return inner_->nv(); }
  void configurationRate(const VecN& q, const VecN& v, VecN& qdot) override { inner_->configurationRate(q, v, qdot); }
  void integrateConfiguration(VecN& q, const VecN& dx, double h) override { inner_->integrateConfiguration(q, dx, h); }
  void normalizeConfiguration(VecN& q) override { inner_->normalizeConfiguration(q); }
  void accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a) override {
    inner_->accelerations(q, v, tau + drive_.torques(q, v), stab, a);
  }
  void constraint(const VecN& q, VecN& phi, MatN& G) override { inner_->constraint(q, phi, G); }
  void baumgarteTerm(const VecN& q, const VecN& v, double zeta, double omega, VecN& s) override { inner_->baumgarteTerm(q, v, zeta, omega, s); }
  void metric(const VecN& q, MatN& W) override { inner_->metric(q, W); }
  bool correction(const VecN& q, const VecN& e, VecN& dx) override { return inner_->correction(q, e, dx); }
  bool recoverDependent(VecN& q, VecN& v) override { return inner_->recoverDependent(q, v); }

 private:
  std::unique_ptr<ConstrainedSystem> inner_;
  Drive drive_;
};

std::string number(double x) { return detail::numberText(x, 6); }

}  // namespace

std::unique_ptr<ConstrainedSystem> withActuators(std::unique_ptr<ConstrainedSystem> engine, const LoadedModel& m) {
  if (m.actuators.empty() && m.tendons.empty()) return engine;
  return std::make_unique<Actuated>(std::move(engine), m);
}

namespace {

// RK4 follows a decaying or oscillating x' = λ x at step h while |R(λ h)| ≤ 1. A mode that does not
// decay (Re λ ≥ 0: a coordinate no servo holds, whose double zero the eigensolver returns as ±1e-8) is
// the motion's own, not the servos'.
bool rk4Follows(std::complex<double> z) {
  return z.real() >= 0 || det::abs(1.0 + z + z * z / 2.0 + z * z * z / 6.0 + z * z * z * z / 24.0) <= 1.0 + 1e-12;
}

// The largest |λ| (det::abs: the same bits on every machine, as the test above).
double fastest(const Eigen::VectorXcd& modes) {
  double r = 0;
  for (Eigen::Index i = 0; i < modes.size(); ++i) r = std::max(r, det::abs(modes[i]));
  return r;
}

bool followsAt(const Eigen::VectorXcd& modes, double h) {
  for (Eigen::Index i = 0; i < modes.size(); ++i)
    if (!rk4Follows(modes[i] * h)) return false;
  return true;
}

}  // namespace

std::string stiffServoNote(const LoadedModel& m, const MatN& M, double dt) {
  const Eigen::Index n = M.rows();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n), C = Eigen::MatrixXd::Zero(n, n);
  for (const Actuator& a : m.actuators)
    for (const TendonTerm& i : a.path)
      for (const TendonTerm& j : a.path) {
        K(i.coordinate, j.coordinate) -= a.gear * a.gear * a.bias[1] * i.coef * j.coef;
        C(i.coordinate, j.coordinate) -= a.gear * a.gear * a.bias[2] * i.coef * j.coef;
      }
  const double k = n ? K.diagonal().maxCoeff() : 0, c = n ? C.diagonal().maxCoeff() : 0;
  if (n == 0 || (k <= 0 && c <= 0)) return "";
  // x = (q, v): x' = [0 1; −M⁻¹K −M⁻¹C] x.
  const Eigen::MatrixXd Minv = Eigen::MatrixXd(M).inverse();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -Minv * K;
  A.bottomRightCorner(n, n) = -Minv * C;
  const Eigen::VectorXcd modes = Eigen::EigenSolver<Eigen::MatrixXd>(A, false).eigenvalues();
  if (!modes.allFinite() || followsAt(modes, dt)) return "";
  double h = dt;
  for (int halvings = 0; halvings < 60 && !followsAt(modes, h); ++halvings) h /= 2;
  return "the servos (stiffness up to " + number(k) + ", damping up to " + number(c) + ", fastest mode " +
         number(fastest(modes)) + " 1/s at the start) are stiffer than RK4 follows at dt " + number(dt) +
         " s: the run chatters; pass --dt " + number(h) + " or less (MuJoCo 3's implicit integrators take these terms implicitly)";
}

namespace {

// "0.5 a + 0.5 b", "a − b"
std::string pathText(const LoadedModel& m, const std::vector<TendonTerm>& path) {
  std::string text;
  for (const TendonTerm& t : path) {
    const double c = std::abs(t.coef);
    text += text.empty() ? (t.coef < 0 ? "−" : "") : (t.coef < 0 ? " − " : " + ");
    text += (c == 1 ? "" : number(c) + " ") + m.joints[std::size_t(t.coordinate)].name;
  }
  return text;
}

}  // namespace

std::string describePath(const LoadedModel& m, const Actuator& a) {
  return a.tendon.empty() ? "joint " + a.joint : "tendon " + a.tendon + " (" + pathText(m, a.path) + ")";
}

std::string describeTendon(const LoadedModel& m, const TendonSpring& t) {
  std::string text = "tendon " + t.name + " (" + pathText(m, t.path) + "):";
  if (t.stiffness != 0) text += " stiffness " + number(t.stiffness) + " about length " + number(t.rest) + ",";
  if (t.damping != 0) text += " damping " + number(t.damping) + ",";
  if (t.frictionloss != 0) text += " frictionloss " + number(t.frictionloss) + ",";
  text.pop_back();
  return text;
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
