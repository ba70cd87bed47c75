// A closed chain in its actuated coordinates (lecture eq. (2) reduced; the five-bar, the slider crank,
// any parallel mechanism). The tree joints θ split into actuated u (named by the caller) and passive w;
// holonomic closure rows φ(θ) = 0 with J = ∂φ/∂θ = [J_u J_w] tie them:
//   velocity      J_u u' + J_w w' = 0                ⇒  θ' = S u',   S = [I; −J_w⁺ J_u]   (rows permuted back)
//   acceleration  J θ'' + J'θ' = 0                   ⇒  θ'' = S u'' + c,   c = [0; −J_w⁺ J'θ']
//   dynamics      Sᵀ(M θ'' + h) = Sᵀ τ = τ_u   (τ on the actuated joints only: Sᵀ[τ_u; 0] = τ_u)
//                 ⇒  M_u u'' + h_u = τ_u,   M_u = Sᵀ M S,   h_u = Sᵀ(M c + h),   G_u = Sᵀ G
//   task point    x' = J_x u',  J_x = J_p S;   x'' = J_x u'' + (J_p c + J'_p θ');   Λ = (J_x M_u⁻¹ J_xᵀ)⁻¹
// The constraint forces drop out (Sᵀ Jᵀ = 0): what a controller of the actuated joints needs, with no
// multiplier. J_w⁺ is a least-squares solve, so rows that repeat others (a loop's dependent rows) do no
// harm; a rank-deficient J_w is a singular configuration (the passive joints are not determined by u:
// the chain can move with the actuators locked) and update() says so. J'θ' comes from the mechanism's
// own solve: J θ'' = −J'θ' for the θ'' of any τ (eq. (2) without stabilisation).
// Also assembly: Newton on φ(θ) = 0 from a guess, the held coordinates (the actuators) kept.
#pragma once
#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <algorithm>
#include <vector>

#include "physics/integrate.h"
#include "physics/types.h"

namespace dyn {

// Assembles q: moves the coordinates not in `held` (minimum-norm Gauss–Newton steps on φ = 0) until
// |φ|∞ ≤ tol. False (q left at the last iterate) if it does not converge in `iterations` steps or
// the free coordinates cannot close the loop there. Works on any ConstrainedSystem's constraint().
inline bool assemble(ConstrainedSystem& mech, VecN& q, const std::vector<int>& held, double tol = 1e-13,
                     int iterations = 50) {
  std::vector<int> free;
  for (int i = 0; i < mech.nq(); ++i)
    if (std::find(held.begin(), held.end(), i) == held.end()) free.push_back(i);
  VecN phi;
  MatN G;
  for (int it = 0; it <= iterations; ++it) {
    mech.constraint(q, phi, G);
    if (phi.size() == 0 || phi.cwiseAbs().maxCoeff() <= tol) return true;
    if (it == iterations || !phi.allFinite()) return false;
    MatN Gf(G.rows(), Eigen::Index(free.size()));
    for (std::size_t j = 0; j < free.size(); ++j) Gf.col(Eigen::Index(j)) = G.col(free[j]);
    const Eigen::CompleteOrthogonalDecomposition<MatN> cod(Gf);
    const VecN dx = cod.solve(phi);
    for (std::size_t j = 0; j < free.size(); ++j) q[free[j]] -= dx[Eigen::Index(j)];
  }
  return false;
}

// M: a ConstrainedMechanism without payloads whose constraints are holonomic closures.
template <class M>
class ClosedChain {
 public:
  using Pos = typename M::Pos;
  // A J_w whose pivots fall below this share of the largest is singular: the passive joints' rates
  // would be amplified by more than 1e6 (within 1e-12 rad of a five-bar's singular pose).
  static constexpr double kSingular = 1e-6;

  // actuated: tree coordinate indices, in the order u lists them.
  ClosedChain(M& mech, std::vector<int> actuated) : mech_(mech), act_(std::move(actuated)) {
    const int n = mech_.n();
    std::vector<char> is_act(std::size_t(n), 0);
    for (int i : act_) is_act[std::size_t(i)] = 1;
    for (int i = 0; i < n; ++i)
      if (!is_act[std::size_t(i)]) pas_.push_back(i);
  }

  int n() const { return mech_.n(); }
  int m() const { return int(act_.size()); }
  const std::vector<int>& actuated() const { return act_; }
  const std::vector<int>& passive() const { return pas_; }

  // Everything at (q, v) = (θ, θ'): S, c, M_u, h_u, G_u. False at a singular configuration (J_w
  // rank-deficient; the other members are then stale).
  bool update(const VecN& q, const VecN& v) {
    const int nn = n(), mm = m(), p = int(pas_.size());
    VecN phi;
    MatN G;
    mech_.constraint(q, phi, G);
    const int r = int(G.rows());
    MatN Ju(r, mm), Jw(r, p);
    for (int j = 0; j < mm; ++j) Ju.col(j) = G.col(act_[std::size_t(j)]);
    for (int j = 0; j < p; ++j) Jw.col(j) = G.col(pas_[std::size_t(j)]);
    // J'θ' = −J θ'' of the unstabilised solve at zero torque.
    VecN a;
    mech_.accelerations(q, v, VecN::Zero(nn), nullptr, a);
    const VecN bias = -(G * a.head(nn));
    S_.setZero(nn, mm);
    c_.setZero(nn);
    if (p > 0) {
      Eigen::ColPivHouseholderQR<MatN> qr(Jw);
      qr.setThreshold(kSingular);
      if (qr.rank() < p) return false;
      const MatN Sw = -qr.solve(Ju);
      const VecN cw = -qr.solve(bias);
      for (int j = 0; j < p; ++j) S_.row(pas_[std::size_t(j)]) = Sw.row(j), c_[pas_[std::size_t(j)]] = cw[j];
    }
    for (int j = 0; j < mm; ++j) S_(act_[std::size_t(j)], j) = 1.0;
    q_ = q.head(nn), v_ = v.head(nn);
    const MatN Mq = mech_.massMatrix(q);
    const VecN h = mech_.inverseDynamics(q, v, VecN::Zero(nn));
    Mu_ = S_.transpose() * Mq * S_;
    hu_ = S_.transpose() * (Mq * c_ + h);
    Gu_ = S_.transpose() * mech_.gravityTorque(q);
    return true;
  }

  const MatN& S() const { return S_; }      // θ' = S u'
  const VecN& c() const { return c_; }      // θ'' = S u'' + c
  const MatN& Mu() const { return Mu_; }    // Sᵀ M S
  const VecN& hu() const { return hu_; }    // Sᵀ(M c + h): Coriolis, centrifugal and gravity in u
  const VecN& Gu() const { return Gu_; }    // Sᵀ G: gravity alone in u

  // A task point (body `link`, body-frame point) at the state of the last update(): its position, the
  // rows `axes` of its spatial velocity map J_x (|axes| × m) and x'' − J_x u'' (the bias).
  void task(int link, const Pos& point, const std::vector<int>& axes, Pos& x, MatN& Jx, VecN& bias) {
    MatN Jp;
    VecN Jdot;
    x = mech_.pointPosition(link, point, q_);
    mech_.pointJacobian(link, point, q_, v_, Jp, Jdot);
    const int k = int(axes.size());
    Jx.resize(k, m());
    bias.resize(k);
    const MatN JS = Jp * S_;
    const VecN Jc = Jp * c_;
    for (int i = 0; i < k; ++i) {
      Jx.row(i) = JS.row(axes[std::size_t(i)]);
      bias[i] = Jc[axes[std::size_t(i)]] + Jdot[axes[std::size_t(i)]];
    }
  }

  // Λ = (J_x M_u⁻¹ J_xᵀ)⁻¹; empty when J_x M_u⁻¹ J_xᵀ is singular (a task singularity).
  MatN taskInertia(const MatN& Jx) const {
    const Eigen::LLT<MatN> Mllt(Mu_);
    if (Mllt.info() != Eigen::Success) return {};
    const MatN inv = Jx * Mllt.solve(Jx.transpose());
    const Eigen::LLT<MatN> L(inv);
    if (L.info() != Eigen::Success) return {};
    return L.solve(MatN::Identity(inv.rows(), inv.cols()));
  }

 private:
  M& mech_;
  std::vector<int> act_, pas_;
  MatN S_, Mu_;
  VecN c_, hu_, Gu_, q_, v_;
};

}  // namespace dyn
