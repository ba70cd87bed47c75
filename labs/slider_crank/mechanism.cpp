// Slider crank through the generic constrained solve, eq. (2); see mechanism.h.
#include "labs/slider_crank/mechanism.h"

#include <cmath>

namespace dyn::slider_crank {
namespace {
const Eigen::Vector3d kA{0.0, 1.0, 0.0};  // the slider moves the tip along world x only

// a = (θ'', α_c) out of a solve of eq. (2) (or (dθ, dx_c) out of its impulse form).
void accelerationsOf(const Mechanism::Solution& s, VecN& a) {
  a.resize(4);
  a.head<3>() = s.qdd;
  a[3] = s.alpha_c[0];
}
}  // namespace

Mechanism::Mechanism(const Params& p) : params_(p), data_(tree_) {
  // Three revolute joints about z; link i+1's joint sits at the end of link i.
  for (int i = 0; i < 3; ++i) {
    const Link& l = p.links[i];
    const Planar::Pos offset = i == 0 ? Planar::Pos::Zero() : Planar::Pos(p.links[i - 1].length, 0.0);
    tree_.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset),
                  Planar::inertia(l.mass, l.com, l.inertia));
  }
  tree_.gravity << 0.0, p.gravity.x(), p.gravity.y();
  data_ = TreeData<Planar>(tree_);
  // The parts of eq. (2) that never change: A, M_c.
  problem_.A = kA;
  problem_.Mc = MatN::Constant(1, 1, p.load_mass);
}

void Mechanism::positionStage(const Eigen::Vector3d& th) {
  // The projection, the trace row and the next step's first stage revisit the same θ.
  if (have_position_ && th == theta_) return;
  // Link transforms, M from CRBA, the tip Jacobian J.
  positionKinematics(tree_, VecN(th), data_);
  problem_.M = crba(tree_, data_);
  MatN J;
  pointJacobian(tree_, data_, 2, tipPoint(), J);
  problem_.J = J;
  factored_ = factor_.factor(problem_, problem_.J, problem_.A);
  theta_ = th;
  have_position_ = true;
}

void Mechanism::velocityStage(const Eigen::Vector3d& thd) {
  const VecN qd = thd;
  // Link velocities, h = Cθ' + G from RNEA with θ'' = 0, and J'θ' at the tip.
  velocityKinematics(tree_, qd, data_);
  problem_.h = rnea(tree_, data_, qd, VecN::Zero(3));
  VecN Jdot_qd;
  pointJacobianDot(tree_, data_, 2, tipPoint(), Jdot_qd);
  problem_.Jdot_qd = Jdot_qd;
}

Mechanism::Solution Mechanism::evaluate(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab) {
  positionStage(q.head<3>());
  velocityStage(v.head<3>());
  problem_.tau = tau;
  if (stab) problem_.stab = *stab;
  else problem_.stab.resize(0);
  if (!factored_) return solveConstrainedBlockLU(problem_);
  Solution s;
  factor_.solve(problem_, s);
  return s;
}

Mechanism::Solution Mechanism::solve(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab) {
  Solution s = evaluate(q, v, tau, stab);
  // Kept: the integrator's first stage usually comes back to this state (the trace row's solve).
  if (!stab) {
    last_q_ = q;
    last_v_ = v;
    last_tau_ = tau;
    last_ = s;
  }
  return s;
}

void Mechanism::accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a) {
  // The state solve() was last asked about: the same answer (a pure function of q, v, τ).
  const bool known = !stab && last_q_.size() && q == last_q_ && v == last_v_ && tau == last_tau_;
  accelerationsOf(known ? last_ : evaluate(q, v, tau, stab), a);
}

void Mechanism::constraint(const VecN& q, VecN& phi, MatN& G) {
  positionStage(q.head<3>());
  const Planar::Pos t = pointPosition(data_, 2, tipPoint());
  phi.resize(3);
  phi << q.head<3>().sum(), t.x() - q[3], t.y();
  // Planar: the position constraint's gradient is the tip Jacobian; G = [J, −A].
  G.resize(3, 4);
  G << problem_.J, -kA;
}

void Mechanism::metric(const VecN& q, MatN& W) {
  positionStage(q.head<3>());
  W = MatN::Zero(4, 4);
  W.topLeftCorner(3, 3) = problem_.M;
  W(3, 3) = std::max(params_.load_mass, 1e-9);
}

bool Mechanism::correction(const VecN& q, const VecN& e, VecN& dx) {
  positionStage(q.head<3>());
  if (!factored_) return ConstrainedSystem::correction(q, e, dx);
  // Eq. (2) for impulses: M dθ = −Jᵀ f, m_c dx_c = Aᵀ f, J dθ − A dx_c = e (τ − h = 0, J'θ' = −e).
  Problem impulse;
  impulse.tau.setZero();
  impulse.h.setZero();
  impulse.Jdot_qd = -e;
  Solution s;
  factor_.solve(impulse, s);
  accelerationsOf(s, dx);  // (dθ, dx_c)
  return dx.allFinite();
}

bool Mechanism::recoverDependent(VecN& q, VecN& v) {
  const auto& L = params_.links;
  const double s12 = -L[0].length * std::sin(q[0]) / L[1].length;
  if (std::abs(s12) > 1.0) return false;
  // Stay on the current branch of cos(θ1+θ2).
  const double branch = std::cos(q[0] + q[1]) >= 0 ? 1.0 : -1.0;
  const double th12 = std::atan2(s12, branch * std::sqrt(1.0 - s12 * s12));
  q[1] = th12 - q[0];
  q[2] = -th12;
  q[3] = tip(q.head(3)).x();
  // Rates: [J_2 J_3 −A] (θ2', θ3', v_c) = −J_1 θ1'.
  MatN J;
  VecN unused;
  tipJacobian(q.head(3), Eigen::Vector3d::Zero(), J, unused);
  Eigen::Matrix3d B;
  B << J.col(1), J.col(2), -kA;
  const Eigen::Vector3d rest = B.fullPivLu().solve(-J.col(0) * v[0]);
  v[1] = rest[0];
  v[2] = rest[1];
  v[3] = rest[2];
  return std::isfinite(v[3]);
}

bool Mechanism::initialState(double theta1, double rate1, int branch, VecN& q, VecN& v) const {
  const auto& L = params_.links;
  const double s12 = -L[0].length * std::sin(theta1) / L[1].length;
  if (std::abs(s12) > 1.0) return false;
  q.resize(4);
  v.resize(4);
  q << theta1, 0, 0, 0;
  v << rate1, 0, 0, 0;
  // The branch is read from cos(θ1+θ2) of the guess: seed it with the requested sign.
  q[1] = (branch >= 0 ? std::asin(s12) : M_PI - std::asin(s12)) - theta1;
  return const_cast<Mechanism*>(this)->recoverDependent(q, v);
}

Eigen::Vector2d Mechanism::tip(const Eigen::Vector3d& th) const { return jointPoints(th)[3]; }

std::array<Eigen::Vector2d, 4> Mechanism::jointPoints(const Eigen::Vector3d& th) const {
  std::array<Eigen::Vector2d, 4> p;
  p[0].setZero();
  double angle = 0;
  for (int i = 0; i < 3; ++i) {
    angle += th[i];
    p[i + 1] = p[i] + params_.links[i].length * Eigen::Vector2d(std::cos(angle), std::sin(angle));
  }
  return p;
}

void Mechanism::tipJacobian(const Eigen::Vector3d& th, const Eigen::Vector3d& rate, MatN& J, VecN& Jdot_qd) {
  positionStage(th);
  velocityKinematics(tree_, VecN(rate), data_);
  J = problem_.J;
  pointJacobianDot(tree_, data_, 2, tipPoint(), Jdot_qd);
}

Eigen::Vector3d Mechanism::gravityTorque(const Eigen::Vector3d& th) {
  const VecN zero = VecN::Zero(3);
  positionStage(th);
  velocityKinematics(tree_, zero, data_);
  return rnea(tree_, data_, zero, zero);
}

double Mechanism::energy(const VecN& q, const VecN& v) {
  positionStage(q.head<3>());
  velocityKinematics(tree_, VecN(v.head(3)), data_);
  // The slider stays at y = 0: only its kinetic energy counts.
  return kineticEnergy(tree_, data_) + potentialEnergy(tree_, data_) + 0.5 * params_.load_mass * v[3] * v[3];
}

double Mechanism::residual(const VecN& q) {
  VecN phi;
  MatN G;
  constraint(q, phi, G);
  return phi.lpNorm<Eigen::Infinity>();
}

}  // namespace dyn::slider_crank
