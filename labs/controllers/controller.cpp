// The controller library: see controller.h.
#include "labs/controllers/controller.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace dyn::controllers {
namespace {

struct KindInfo {
  const char* name;
  Kind kind;
  std::vector<std::string> gains;
};
const std::vector<KindInfo>& kinds() {
  static const std::vector<KindInfo> k = {
      {"none", Kind::None, {}},
      {"constant", Kind::Constant, {}},
      {"joint_pd_gravity", Kind::JointPdGravity, {"kp", "kd"}},
      {"pid", Kind::Pid, {"kp", "ki", "kd"}},
      {"computed_torque", Kind::ComputedTorque, {"omega_n", "zeta"}},
      {"task_pd_gravity", Kind::TaskPdGravity, {"kp", "kd"}},
      {"task_inverse_dynamics", Kind::TaskInverseDynamics, {"omega_n", "zeta"}},
      {"impedance_task", Kind::ImpedanceTask, {"k_imp", "d_imp"}},
      {"impedance_inverse_dynamics", Kind::ImpedanceInverseDynamics, {"k_imp", "d_imp", "m_imp"}},
      {"impedance_joint", Kind::ImpedanceJoint, {"k_imp", "d_imp", "m_imp", "omega_n", "zeta"}}};
  return k;
}

// x = J⁻¹ b for a square task Jacobian, least squares otherwise.
VecN solveTask(const MatN& J, const VecN& b) { return J.colPivHouseholderQr().solve(b); }

}  // namespace

const std::vector<std::string>& kindNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& k : kinds()) n.push_back(k.name);
    return n;
  }();
  return names;
}

Kind kindFromName(const std::string& name) {
  for (const auto& k : kinds())
    if (name == k.name) return k.kind;
  throw std::invalid_argument("unknown controller kind " + name);
}

std::vector<std::string> gainsOf(Kind kind) {
  for (const auto& k : kinds())
    if (k.kind == kind) return k.gains;
  return {};
}

Controller::Controller(const Spec& spec, const MechanismModel<Spatial>& model, std::vector<int> actuated, TaskPoint task,
                       const VecN& q0, double dt)
    : spec_(spec), mech_(std::make_unique<Mech>(model)), chain_(*mech_, std::move(actuated)), task_(std::move(task)),
      hold_(std::max(1L, std::lround(spec.period / dt))), dt_(dt), rng_(spec.seed), q_ik_(q0) {
  const int m = chain_.m();
  integral_ = VecN::Zero(m);
  e_u_ = VecN::Zero(m);
  if (spec_.joint_scale.size() != m) spec_.joint_scale = VecN::Ones(m);
  tau_u_ = VecN::Zero(m);
  tau_ = VecN::Zero(mech_->n());
  u0_ = VecN(m);
  for (int j = 0; j < m; ++j) u0_[j] = q0[chain_.actuated()[std::size_t(j)]];
}

void Controller::taskPosition(const VecN& q, VecN& x) {
  const Eigen::Vector3d p = mech_->pointPosition(task_.link, task_.point, q);
  x.resize(Eigen::Index(task_.axes.size()));
  for (std::size_t i = 0; i < task_.axes.size(); ++i) x[Eigen::Index(i)] = p[task_.axes[i] - 3];
}

bool inverseKinematics(ConstrainedMechanism<Spatial>& mech, const TaskPoint& task, const VecN& x_d, VecN& q) {
  const int n = mech.n(), d = int(task.axes.size());
  for (int it = 0; it < 30; ++it) {
    VecN phi, x(d), jd;
    MatN G, Jp;
    mech.constraint(q, phi, G);
    const Eigen::Vector3d p = mech.pointPosition(task.link, task.point, q);
    for (int i = 0; i < d; ++i) x[i] = p[task.axes[std::size_t(i)] - 3];
    mech.pointJacobian(task.link, task.point, q, VecN::Zero(n), Jp, jd);
    const int r = int(phi.size());
    VecN f(r + d);
    MatN A(r + d, n);
    f.head(r) = phi, A.topRows(r) = G.leftCols(n);
    f.tail(d) = x - x_d;
    for (int i = 0; i < d; ++i) A.row(r + i) = Jp.row(task.axes[std::size_t(i)]);
    if (f.cwiseAbs().maxCoeff() < 1e-12) return true;
    q.head(n) -= Eigen::CompleteOrthogonalDecomposition<MatN>(A).solve(f);
    if (!q.allFinite()) return false;
  }
  return false;
}

bool Controller::inverseKinematics(const VecN& x_d, VecN& q) { return controllers::inverseKinematics(*mech_, task_, x_d, q); }

// The joint motion that makes the task point move as (x, x', x''): inverse kinematics on the
// controller's model, then u_d' = J_x⁻¹ x', u_d'' = J_x⁻¹ (x'' − J_x' u_d') (minimum-norm solutions when
// `min_norm`: more joints than task axes); false where the pose is out of reach or singular.
bool Controller::jointMotion(const VecN& x, const VecN& xd, const VecN& xdd, bool min_norm, VecN& ud, VecN& ud_d, VecN& udd_d) {
  auto solve = [min_norm](const MatN& J, const VecN& b) {
    return min_norm ? VecN(Eigen::CompleteOrthogonalDecomposition<MatN>(J).solve(b)) : solveTask(J, b);
  };
  Eigen::Vector3d p;
  MatN Jx;
  VecN bias;
  if (!inverseKinematics(x, q_ik_) || !chain_.update(q_ik_, VecN::Zero(mech_->n()))) return false;
  chain_.task(task_.link, task_.point, task_.axes, p, Jx, bias);
  ud_d = solve(Jx, xd);
  if (!chain_.update(q_ik_, chain_.S() * ud_d)) return false;
  chain_.task(task_.link, task_.point, task_.axes, p, Jx, bias);
  udd_d = solve(Jx, VecN(xdd - bias));
  const auto& act = chain_.actuated();
  ud = VecN(chain_.m());
  for (int j = 0; j < chain_.m(); ++j) ud[j] = q_ik_[act[std::size_t(j)]];
  return true;
}

VecN Controller::law(const VecN& q, const VecN& v, const Reference& ref, const VecN& force) {
  const int m = chain_.m();
  const auto& act = chain_.actuated();
  const Kind kind = spec_.kind;
  if (kind == Kind::None) return VecN::Zero(m);
  if (kind == Kind::Constant) return spec_.constant;
  Eigen::Vector3d p;
  MatN Jx;
  VecN bias;
  // The desired joint motion (joint laws): inverse kinematics, then rates and accelerations through J_x.
  VecN ud, udd_d = VecN::Zero(m), ud_d = VecN::Zero(m);
  const bool joint = kind == Kind::JointPdGravity || kind == Kind::Pid || kind == Kind::ComputedTorque;
  if (joint && ref.joint) {
    ud = ref.x, ud_d = ref.xd, udd_d = ref.xdd;
  } else if (joint && !jointMotion(ref.x, ref.xd, ref.xdd, false, ud, ud_d, udd_d)) {
    return tau_u_;
  }
  if (kind == Kind::ImpedanceJoint) {
    // The impedance model on the measured force about the reference, then inverse kinematics.
    const int d = int(task_.axes.size());
    if (x_des_.size() != d) x_des_ = ref.x, v_des_ = VecN::Zero(d);
    const VecN K = VecN::Constant(d, spec_.k_imp), D = VecN::Constant(d, spec_.d_imp), M = VecN::Constant(d, spec_.m_imp);
    const VecN a_des = laws::impedanceAcceleration(force, M, D, K, x_des_, VecN(v_des_ - ref.xd), ref.x) + ref.xdd;
    const double h = double(hold_) * dt_;
    v_des_ += h * a_des;
    x_des_ += h * v_des_;
    if (!jointMotion(x_des_, v_des_, a_des, true, ud, ud_d, udd_d)) return tau_u_;
  }
  if (!chain_.update(q, v)) return tau_u_;  // a singular pose: hold the last command
  VecN u(m), w(m);
  for (int j = 0; j < m; ++j) u[j] = q[act[std::size_t(j)]], w[j] = v[act[std::size_t(j)]];
  // Joint laws: gains per joint (joint_scale); computed torque's set the error dynamics, the same on each.
  const double wn = spec_.omega_n;
  const VecN& s = spec_.joint_scale;
  const VecN kp = spec_.kp * s, kd = spec_.kd * s, kp2 = VecN::Constant(m, wn * wn), kd2 = VecN::Constant(m, 2.0 * spec_.zeta * wn);
  switch (kind) {
    case Kind::JointPdGravity: return laws::pdGravity(kp, VecN(ud - u), kd, VecN(ud_d - w), chain_.Gu());
    case Kind::Pid: {
      // u_I advances in torque() once the clipped output is known (anti-windup reads it).
      e_u_ = ud - u;
      VecN tau = laws::pid(kp, e_u_, kd, VecN(ud_d - w), integral_);
      if (spec_.coulomb_compensation)
        for (int j = 0; j < m; ++j) {
          const auto& joints = mech_->model().joints;
          const std::size_t i = std::size_t(act[std::size_t(j)]);
          const double fc = i < joints.size() ? joints[i].coulomb : 0.0;
          tau[j] += laws::coulombCompensation(fc, ud_d[j], spec_.compensation_width);
        }
      return tau;
    }
    case Kind::ComputedTorque:
    case Kind::ImpedanceJoint:
      return chain_.Mu() * laws::computedTorqueAcceleration(udd_d, kp2, VecN(ud - u), kd2, VecN(ud_d - w)) + chain_.hu();
    default: break;
  }
  chain_.task(task_.link, task_.point, task_.axes, p, Jx, bias);
  const int d = int(task_.axes.size());
  VecN x(d);
  for (int i = 0; i < d; ++i) x[i] = p[task_.axes[std::size_t(i)] - 3];
  const VecN xdot = Jx * w, e = ref.x - x, ed = ref.xd - xdot;
  if (kind == Kind::TaskPdGravity)
    return laws::taskPdGravity(chain_.Gu(), Jx, VecN::Constant(d, spec_.kp), e, VecN::Constant(d, spec_.kd), ed);
  if (kind == Kind::ImpedanceTask || kind == Kind::ImpedanceInverseDynamics) return impedance(Jx, bias, x, xdot, u, w, ref, force);
  // Task inverse dynamics: the task acceleration asked for, mapped to u'' through J_x.
  const VecN a = laws::computedTorqueAcceleration(ref.xdd, VecN::Constant(d, wn * wn), e, VecN::Constant(d, 2.0 * spec_.zeta * wn), ed);
  return chain_.Mu() * solveTask(Jx, a - bias) + chain_.hu();
}

// The impedance laws (controller.h): Λ, J̄ and the null-space posture at the state of the last update.
VecN Controller::impedance(const MatN& Jx, const VecN& bias, const VecN& x, const VecN& xdot, const VecN& u, const VecN& w,
                           const Reference& ref, const VecN& force) {
  const int d = int(x.size()), m = int(u.size());
  const VecN k = VecN::Constant(d, spec_.k_imp), D = VecN::Constant(d, spec_.d_imp), M = VecN::Constant(d, spec_.m_imp);
  const MatN Lambda = chain_.taskInertia(Jx);
  if (Lambda.size() == 0) return tau_u_;  // a task singularity: hold the last command
  // The posture in the null space: Nᵀ M_u a_0, Nᵀ = I − J_xᵀ J̄ᵀ, J̄ = M_u⁻¹ J_xᵀ Λ.
  VecN tau_n = VecN::Zero(m);
  if (spec_.posture_omega > 0) {
    const double w0 = spec_.posture_omega;
    const MatN Jbar = Eigen::LLT<MatN>(chain_.Mu()).solve(Jx.transpose()) * Lambda;
    const MatN Nt = MatN::Identity(m, m) - Jx.transpose() * Jbar.transpose();
    tau_n = Nt * (chain_.Mu() * VecN(w0 * w0 * (u0_ - u) - 2.0 * w0 * w));
  }
  if (spec_.kind == Kind::ImpedanceTask)
    return laws::taskPdGravity(chain_.Gu(), Jx, k, VecN(ref.x - x), D, VecN(ref.xd - xdot)) + tau_n;
  // Force feedback: the target's acceleration about the reference, made the tool's by M_u J̄ = J_xᵀ Λ.
  const VecN a = laws::impedanceAcceleration(force, M, D, k, x, VecN(xdot - ref.xd), ref.x) + ref.xdd;
  return Jx.transpose() * (Lambda * (a - bias) - force) + chain_.hu() + tau_n;
}

VecN Controller::torque(double t, const VecN& q, const VecN& v, const Reference& ref) {
  (void)t;
  readings_.push_back({q, v, ref.force});
  while (long(readings_.size()) > spec_.delay_steps + 1) readings_.pop_front();
  if (k_++ % hold_ != 0) return tau_;
  // What the encoders (and the force sensor) report: the reading `delay` steps old, with noise.
  VecN qm = readings_.front().q, vm = readings_.front().v;
  if (spec_.noise_angle > 0 || spec_.noise_rate > 0)
    for (int i = 0; i < mech_->n(); ++i) qm[i] += spec_.noise_angle * normal_(rng_), vm[i] += spec_.noise_rate * normal_(rng_);
  VecN fm = readings_.front().force;
  if (fm.size() != Eigen::Index(task_.axes.size())) fm = VecN::Zero(Eigen::Index(task_.axes.size()));
  if (spec_.noise_force > 0)
    for (int i = 0; i < fm.size(); ++i) fm[i] += spec_.noise_force * normal_(rng_);
  VecN u = law(qm, vm, ref, fm);
  for (int j = 0; j < u.size(); ++j)
    if (!std::isfinite(u[j])) u[j] = 0.0;
  const VecN raw = u;
  saturated_ = laws::saturate(u, spec_.torque_limit);
  if (spec_.kind == Kind::Pid)
    laws::integrate(integral_, spec_.anti_windup, VecN(spec_.ki * spec_.joint_scale), e_u_, raw, u, spec_.torque_limit,
                    spec_.tracking_time, double(hold_) * dt_);
  tau_u_ = u;
  tau_.setZero();
  for (int j = 0; j < u.size(); ++j) tau_[chain_.actuated()[std::size_t(j)]] = u[j];
  return tau_;
}

}  // namespace dyn::controllers
