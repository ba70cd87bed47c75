// Eqs. (2)/(3): the payload acceleration α_c and the constraint force solved together, by the
// range-space (Schur complement) route of the lecture. With J̃ = H̃ J, Ã = H̃ A (H̃ = I for eq. 2):
//   M = L D Lᵀ   (Cholesky, cholesky.h)
//   Λ = J̃ M⁻¹ J̃ᵀ,   r = J̃ M⁻¹ (τ − h) + H̃ (J'θ' + H'w − A'v_c − s)   (the right-hand side of (2)/(3))
//   second row   Ã α_c + Λ η = r                 ⇒  η = Λ⁻¹ (r − Ã α_c)
//   first row    M_c α_c − Ãᵀ η = −b_c − G_c     ⇒  (M_c + Ãᵀ Λ⁻¹ Ã) α_c = −b_c − G_c + Ãᵀ Λ⁻¹ r
//   tree         θ'' = M⁻¹ (τ − h − J̃ᵀ η)
// M, Λ and the Schur complement are symmetric positive definite away from singular
// configurations; when one is not, the whole block matrix goes to a full-pivot LU instead.
// Written once for fixed and bounded sizes (constrained.h); include this to solve fixed sizes.
#pragma once
#include "physics/cholesky.h"
#include "physics/constrained.h"

namespace dyn {
namespace detail {

// Capacity of a size that may be dynamic.
constexpr int cap(int n) { return n == Eigen::Dynamic ? kMaxDof : n; }
constexpr int plus1(int n) { return n == Eigen::Dynamic ? Eigen::Dynamic : n + 1; }

// The Schur route on the constrained rows J̃ (m'×n) and Ã (m'×k); false if a factor is not
// positive definite. H̃ is p.Ht when there are contacts, else the identity.
template <int Nj, int Nr, int Nl, class JT, class AT>
bool solveSchur(const ConstrainedProblemT<Nj, Nr, Nl>& p, const JT& J, const AT& A,
                ConstrainedSolutionT<Nj, Nr, Nl>& s) {
  constexpr int R = JT::RowsAtCompileTime;  // m' = m, or the contact rows (dynamic)
  const int n = int(p.M.rows()), k = int(A.cols()), m = int(J.rows());
  const bool contacts = p.Ht.size() > 0;
  CholeskyN<Nj> chol_M;
  if (!chol_M.compute(p.M)) return false;

  // Y = L⁻¹ [J̃ᵀ  τ − h]: one forward substitution for the rows and the free acceleration.
  MatRC<Nj, plus1(R), cap(Nj), cap(R) + 1> Y(n, m + 1);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < m; ++j) Y(i, j) = J(j, i);
    Y(i, m) = p.tau[i] - p.h[i];
  }
  chol_M.forward(Y);
  // Their M⁻¹ inner products: Λ = J̃ M⁻¹ J̃ᵀ (first m columns) and J̃ M⁻¹ (τ − h) (the last).
  MatRC<R, plus1(R), cap(R), cap(R) + 1> G(m, m + 1);
  chol_M.inner(Y, m, G);
  CholeskyN<R> chol_L;
  if (!chol_L.compute(G, m)) return false;  // factors the leading m×m block, Λ

  // R = Λ⁻¹ [Ã  r],  r = J̃ M⁻¹ (τ − h) + H̃ (J'θ' + H'w − A'v_c − s): the second row, η given α_c.
  MatRC<Nr, 1> bias = p.Jdot_qd;
  if (p.Adot_vc.size()) bias -= p.Adot_vc;
  if (p.Hdot_w.size()) bias += p.Hdot_w;
  if (p.stab.size()) bias -= p.stab;
  MatRC<R, plus1(Nl), cap(R), cap(Nl) + 1> Rm(m, k + 1);
  for (int i = 0; i < m; ++i) {
    for (int j = 0; j < k; ++j) Rm(i, j) = A(i, j);
    Rm(i, k) = G(i, m) + (contacts ? p.Ht.row(i).dot(bias) : bias[i]);
  }
  chol_L.solveInPlace(Rm);

  // The first row: (M_c + Ãᵀ Λ⁻¹ Ã) α_c = −b_c − G_c + Ãᵀ Λ⁻¹ r.
  MatRC<Nl, plus1(Nl), cap(Nl), cap(Nl) + 1> Sc(k, k + 1);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j <= k; ++j) {
      double x = 0;
      for (int r = 0; r < m; ++r) x += A(r, i) * Rm(r, j);
      Sc(i, j) = x;
    }
  for (int i = 0; i < k; ++i) {
    for (int j = 0; j < k && p.Mc.size(); ++j) Sc(i, j) += p.Mc(i, j);
    if (p.bc_Gc.size()) Sc(i, k) -= p.bc_Gc[i];
  }
  CholeskyN<Nl> chol_S;
  if (!chol_S.compute(Sc, k)) return false;
  s.alpha_c.resize(k);
  for (int i = 0; i < k; ++i) s.alpha_c[i] = Sc(i, k);
  chol_S.solveInPlace(s.alpha_c);

  // η = Λ⁻¹ r − Λ⁻¹ Ã α_c, and the spatial force f = H̃ᵀ η.
  s.eta.resize(m);
  for (int i = 0; i < m; ++i) {
    double e = Rm(i, k);
    for (int j = 0; j < k; ++j) e -= Rm(i, j) * s.alpha_c[j];
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
  chol_M.scale(s.qdd);
  chol_M.backward(s.qdd);
  s.ok = true;
  return true;
}

}  // namespace detail

template <int Nj, int Nr, int Nl>
ConstrainedSolutionT<Nj, Nr, Nl> solveConstrained(const ConstrainedProblemT<Nj, Nr, Nl>& p) {
  ConstrainedSolutionT<Nj, Nr, Nl> s;
  const bool done = p.Ht.size() > 0
                        ? detail::solveSchur(p, MatN(p.Ht * p.J), MatN(p.Ht * p.A), s)
                        : detail::solveSchur(p, p.J, p.A, s);
  if (done) return s;
  // (Nearly) singular: the pivoted LU of the bounded-size problem judges.
  if constexpr (Nj == Eigen::Dynamic && Nr == Eigen::Dynamic && Nl == Eigen::Dynamic) {
    return solveConstrainedBlockLU(p);
  } else {
    ConstrainedProblem d{p.M, p.h, p.tau, p.J, p.Jdot_qd, p.A, p.Adot_vc, p.Mc, p.bc_Gc, p.Ht, p.Hdot_w, p.stab};
    const ConstrainedSolution x = solveConstrainedBlockLU(d);
    s.alpha_c = x.alpha_c;
    s.eta = x.eta;
    s.f = x.f;
    s.qdd = x.qdd;
    s.ok = x.ok;
    return s;
  }
}

}  // namespace dyn
