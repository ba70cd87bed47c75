// Eqs. (2)/(3): the payload acceleration α_c and the constraint force solved together, by the
// range-space (Schur complement) route of the lecture. With J̃ = H̃ J, Ã = H̃ A (H̃ = I for eq. 2):
//   M = L D Lᵀ   (Cholesky, cholesky.h)
//   Λ = J̃ M⁻¹ J̃ᵀ,   r = J̃ M⁻¹ (τ − h) + H̃ (J'θ' + H'w − A'v_c − s)   (the right-hand side of (2)/(3))
//   second row   Ã α_c + Λ η = r                 ⇒  η = Λ⁻¹ (r − Ã α_c)
//   first row    M_c α_c − Ãᵀ η = −b_c − G_c     ⇒  (M_c + Ãᵀ Λ⁻¹ Ã) α_c = −b_c − G_c + Ãᵀ Λ⁻¹ r
//   tree         θ'' = M⁻¹ (τ − h − J̃ᵀ η)
// M, Λ and the Schur complement are symmetric positive definite away from singular
// configurations; when one is not, the whole block matrix goes to a full-pivot LU instead.
#include "physics/constrained.h"

#include <Eigen/LU>

#include "physics/cholesky.h"

namespace dyn {
namespace {

// C = Aᵀ B (small sizes: plain loops, no temporaries).
template <class MA, class MB>
void transposeTimes(const MA& a, const MB& b, MatN& c) {
  c.resize(a.cols(), b.cols());
  for (int i = 0; i < int(a.cols()); ++i)
    for (int j = 0; j < int(b.cols()); ++j) {
      double s = 0;
      for (int k = 0; k < int(a.rows()); ++k) s += a(k, i) * b(k, j);
      c(i, j) = s;
    }
}

// The Schur complement route; false if a factor is not positive definite.
bool solveSchur(const ConstrainedProblem& p, ConstrainedSolution& s) {
  const int n = int(p.M.rows());
  const int k = int(p.A.cols());
  Cholesky M;
  if (!M.compute(p.M)) return false;

  // The constrained rows J̃ = H̃ J, Ã = H̃ A.
  const bool contacts = p.Ht.size() > 0;
  MatN HJ, HA;
  if (contacts) {
    HJ.noalias() = p.Ht * p.J;
    HA.noalias() = p.Ht * p.A;
  }
  const MatN& J = contacts ? HJ : p.J;
  const MatN& A = contacts ? HA : p.A;
  const int m = int(J.rows());

  // Y = L⁻¹ [J̃ᵀ  τ − h]: one forward substitution for the rows and the free acceleration.
  MatN Y(n, m + 1);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) Y(i, j) = J(j, i);
    Y(i, m) = p.tau[i] - p.h[i];
  }
  M.forward(Y);
  // Their M⁻¹ inner products: Λ = J̃ M⁻¹ J̃ᵀ (first m columns) and J̃ M⁻¹ (τ − h) (the last).
  MatN G;
  M.inner(Y, m, G);
  Cholesky Lambda;
  if (!Lambda.compute(G)) return false;  // factors the leading m×m block, Λ

  // R = Λ⁻¹ [Ã  r],  r = J̃ M⁻¹ (τ − h) + H̃ (J'θ' + H'w − A'v_c − s): the second row, η given α_c.
  VecN bias = p.Jdot_qd;
  if (p.Adot_vc.size()) bias -= p.Adot_vc;
  if (p.Hdot_w.size()) bias += p.Hdot_w;
  if (p.stab.size()) bias -= p.stab;
  MatN R(m, k + 1);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < k; ++j) R(i, j) = A(i, j);
    R(i, k) = G(i, m) + (contacts ? p.Ht.row(i).dot(bias) : bias[i]);
  }
  Lambda.solveInPlace(R);

  // The first row: (M_c + Ãᵀ Λ⁻¹ Ã) α_c = −b_c − G_c + Ãᵀ Λ⁻¹ r.
  MatN Sc;
  transposeTimes(A, R, Sc);
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k && p.Mc.size(); ++j) Sc(i, j) += p.Mc(i, j);
    if (p.bc_Gc.size()) Sc(i, k) -= p.bc_Gc[i];
  }
  Cholesky C;
  if (!C.compute(Sc)) return false;
  s.alpha_c = Sc.col(k);
  C.solveInPlace(s.alpha_c);

  // η = Λ⁻¹ r − Λ⁻¹ Ã α_c, and the spatial force f = H̃ᵀ η.
  s.eta.resize(m);
  for (int i = 0; i < m; ++i) {
    double e = R(i, k);
    for (int j = 0; j < k; ++j) e -= R(i, j) * s.alpha_c[j];
    s.eta[i] = e;
  }
  if (contacts) s.f.noalias() = p.Ht.transpose() * s.eta;
  else s.f = s.eta;
  // θ'' = M⁻¹ (τ − h − J̃ᵀ η) = L⁻ᵀ D⁻¹ (L⁻¹ (τ − h) − L⁻¹ J̃ᵀ η).
  s.qdd.resize(n);
  for (int i = 0; i < n; ++i) {
    double a = Y(i, m);
    for (int j = 0; j < m; ++j) a -= Y(i, j) * s.eta[j];
    s.qdd[i] = a;
  }
  M.scale(s.qdd);
  M.backward(s.qdd);
  s.ok = true;
  return true;
}

}  // namespace

ConstrainedSolution solveConstrained(const ConstrainedProblem& p) {
  ConstrainedSolution s;
  if (!solveSchur(p, s)) s = solveConstrainedBlockLU(p);  // (nearly) singular: the pivoted LU judges
  return s;
}

ConstrainedSolution solveConstrainedBlockLU(const ConstrainedProblem& p) {
  const int m = int(p.J.rows());
  const int k = int(p.A.cols());
  const bool contacts = p.Ht.size() > 0;
  const int r = contacts ? int(p.Ht.rows()) : m;

  // Tree part: M⁻¹ (τ − h) and M⁻¹ J^T.
  const Eigen::LLT<MatN> llt(p.M);
  const VecN qdd_free = llt.solve(p.tau - p.h);
  const MatN Minv_JT = llt.solve(p.J.transpose());

  // Acceleration row before projection onto the constrained directions.
  VecN rhs_acc = p.J * qdd_free + p.Jdot_qd;
  if (p.Adot_vc.size()) rhs_acc -= p.Adot_vc;
  if (p.Hdot_w.size()) rhs_acc += p.Hdot_w;
  if (p.stab.size()) rhs_acc -= p.stab;

  // H̃-projected blocks: H̃ A, H̃ J M⁻¹ J^T H̃^T, H̃ rhs.
  MatN HA, Lambda;
  VecN rhs_eta;
  if (contacts) {
    HA = p.Ht * p.A;
    const MatN JMinvJT = p.J * Minv_JT;
    Lambda = p.Ht * JMinvJT * p.Ht.transpose();
    rhs_eta = p.Ht * rhs_acc;
  } else {
    HA = p.A;
    Lambda = p.J * Minv_JT;
    rhs_eta = rhs_acc;
  }

  // The (k + r) block system, solved with pivoted LU (indefinite when M_c = 0).
  MatN K = MatN::Zero(k + r, k + r);
  VecN b(k + r);
  if (p.Mc.size()) K.topLeftCorner(k, k) = p.Mc;
  K.topRightCorner(k, r) = -HA.transpose();
  K.bottomLeftCorner(r, k) = HA;
  K.bottomRightCorner(r, r) = Lambda;
  b.head(k) = p.bc_Gc.size() ? VecN(-p.bc_Gc) : VecN(VecN::Zero(k));
  b.tail(r) = rhs_eta;
  const Eigen::FullPivLU<MatN> lu(K);

  ConstrainedSolution s;
  s.ok = lu.isInvertible() && llt.info() == Eigen::Success;
  const VecN x = lu.solve(b);
  s.alpha_c = x.head(k);
  s.eta = x.tail(r);
  s.f = contacts ? VecN(p.Ht.transpose() * s.eta) : s.eta;
  s.qdd = qdd_free - Minv_JT * s.f;
  return s;
}

}  // namespace dyn
