// Eqs. (2)/(3): the payload acceleration α_c and the constraint force solved together, by the
// range-space (Schur complement) route of the lecture. With J̃ = H̃ J, Ã = H̃ A (H̃ = I for eq. 2):
//   M = L D Lᵀ   (Cholesky, cholesky.h)
//   Λ = J̃ M⁻¹ J̃ᵀ,   r = J̃ M⁻¹ (τ − h) + H̃ (J'θ' + H'w − A'v_c − s)   (the right-hand side of (2)/(3))
//   second row   Ã α_c + Λ η = r                 ⇒  η = Λ⁻¹ (r − Ã α_c)
//   first row    M_c α_c − Ãᵀ η = −b_c − G_c     ⇒  (M_c + Ãᵀ Λ⁻¹ Ã) α_c = −b_c − G_c + Ãᵀ Λ⁻¹ r
//   tree         θ'' = M⁻¹ (τ − h − J̃ᵀ η)
// M, Λ and the Schur complement are symmetric positive definite away from singular
// configurations; when one is not, the whole block matrix goes to a full-pivot LU instead.
// Rows that lock coordinates (J̃ row i = −σ_i e_cᵢᵀ, distinct cᵢ, no payload: joint limits at their
// stops) are eliminated instead (factorLocked): J̃ θ'' = −b fixes θ''_L, the free coordinates F solve
//   M_FF θ''_F = (τ − h)_F − M_FL θ''_L,      and   η_i = σ_i (M_cᵢ· θ'' + h_cᵢ − τ_cᵢ)
// (row cᵢ of M θ'' + h − τ = −J̃ᵀ η): one factor and one substitution, no Λ.
// Written once for fixed and bounded sizes (constrained.h); include this to solve fixed sizes.
#pragma once
#include "physics/cholesky.h"
#include "physics/constrained.h"

namespace dyn {
// The Schur route in two parts: factor() everything that depends on the configuration alone
// (M, J̃, Ã, M_c: the factors of M, Λ and the Schur complement), then solve() for any right-hand
// side (τ − h, J'θ', ... : the state's velocities and torques). A mechanism factors once per
// configuration and solves for every stage, the trace row and the projection (which is the same
// solve with impulses: integrate.h). Nr is m, the rows of J̃: the constraint rows without contacts,
// H̃'s rows (dynamic) with them.
template <int Nj, int Nr, int Nl>
class ConstrainedFactorT {
 public:
  // Factors for J̃ (m×n) and Ã (m×k); false if M, Λ or the Schur complement is not clearly
  // positive definite (then the caller goes to the pivoted LU).
  template <class Problem, class JT, class AT>
  bool factor(const Problem& p, const JT& J, const AT& A) {
    n_ = int(p.M.rows());
    m_ = int(J.rows());
    k_ = int(A.cols());
    locked_ = false;
    const int n = this->n(), m = this->m(), k = this->k();  // compile-time where the sizes are fixed
    if (!chol_M_.compute(p.M)) return false;
    // Y = L⁻¹ J̃ᵀ, and Λ = J̃ M⁻¹ J̃ᵀ = Yᵀ D⁻¹ Y.
    Y_.resize(n, m);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < m; ++j) Y_(i, j) = J(j, i);
    chol_M_.forward(Y_);
    MatRC<Nr, Nr> Lambda(m, m);
    chol_M_.inner(Y_, m, Lambda);
    if (p.compliance.size())
      for (int i = 0; i < m; ++i) Lambda(i, i) += p.compliance[i];
    if (!chol_L_.compute(Lambda, m)) return false;
    // Λ⁻¹ Ã, and the Schur complement S = M_c + Ãᵀ Λ⁻¹ Ã.
    A_.resize(m, k);
    LA_.resize(m, k);
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < k; ++j) A_(i, j) = LA_(i, j) = A(i, j);
    chol_L_.solveInPlace(LA_);
    MatRC<Nl, Nl> S(k, k);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) {
        double x = p.Mc.size() ? p.Mc(i, j) : 0.0;
        for (int r = 0; r < m; ++r) x += A_(r, i) * LA_(r, j);
        S(i, j) = x;
      }
    return chol_S_.compute(S, k);
  }

  // Factors for m rows that lock coordinates, row i J̃ = −sign[i] e_cᵀ with c = coordinate[i] (distinct),
  // and no payload (see the top): M_FF's factor as M's with the locked rows and columns replaced by the
  // identity's times M's largest diagonal entry (so the pivot test is M's own). Their entries of L are
  // then zero: the free part is M_FF's factor, and what stands in a locked coordinate during a
  // substitution never reaches a free one. False if M_FF is not clearly positive definite.
  template <class Problem>
  bool factorLocked(const Problem& p, const int* coordinate, const double* sign, int m) {
    n_ = int(p.M.rows());
    m_ = m;
    k_ = 0;
    locked_ = true;
    const int n = this->n();
    double largest = 0;
    for (int i = 0; i < n; ++i) largest = std::max(largest, std::abs(p.M(i, i)));
    bool locked[kCap] = {};
    Mcol_.resize(n, m);
    for (int r = 0; r < m; ++r) {
      const int c = coordinate[r];
      coordinate_[r] = c;
      sign_[r] = sign[r];
      locked[c] = true;
      for (int i = 0; i < n; ++i) Mcol_(i, r) = p.M(i, c);  // M_Fc and M_cc for the right-hand side and η
    }
    // M so modified, read in place: a copy of M (a block move the CPU starts slowly, of entries CRBA has
    // just stored) costs more than the factor's few reads through the test.
    return chol_M_.compute(LockedInertia<std::decay_t<decltype(p.M)>>{p.M, locked, largest});
  }

  // The solution at p's right-hand side (τ − h, J'θ', A'v_c, H'w, s, b_c + G_c), with the
  // configuration last factored. Ht as in p (empty: eq. 2). Without with_qdd: α_c, η, f only.
  template <class Problem, class Solution>
  void solve(const Problem& p, Solution& s, bool with_qdd = true) const {
    if constexpr (Nr == Eigen::Dynamic)
      if (locked_) return solveLocked(p, s);
    const int n = this->n(), m = this->m(), k = this->k();  // compile-time where the sizes are fixed
    // y = L⁻¹ (τ − h), and r = J̃ M⁻¹ (τ − h) + H̃ (J'θ' + H'w − A'v_c − s).
    MatRC<Nj, 1> y(n);
    for (int i = 0; i < n; ++i) y[i] = p.tau[i] - p.h[i];
    chol_M_.forward(y);
    MatRC<Nr, 1> r(m);
    chol_M_.inner(Y_, m, y, r);
    auto bias = p.Jdot_qd.eval();
    if (p.Adot_vc.size()) bias -= p.Adot_vc;
    if (p.Hdot_w.size()) bias += p.Hdot_w;
    if (p.stab.size()) bias -= p.stab;
    const bool contacts = p.Ht.size() > 0;
    for (int i = 0; i < m; ++i) r[i] += contacts ? p.Ht.row(i).dot(bias) : bias[i];
    chol_L_.solveInPlace(r);  // Λ⁻¹ r
    // The first row: S α_c = −b_c − G_c + Ãᵀ Λ⁻¹ r.
    s.alpha_c.resize(k);
    for (int i = 0; i < k; ++i) {
      double x = p.bc_Gc.size() ? -p.bc_Gc[i] : 0.0;
      for (int j = 0; j < m; ++j) x += A_(j, i) * r[j];
      s.alpha_c[i] = x;
    }
    chol_S_.solveInPlace(s.alpha_c);
    // η = Λ⁻¹ r − Λ⁻¹ Ã α_c, and the spatial force f = H̃ᵀ η.
    s.eta.resize(m);
    for (int i = 0; i < m; ++i) {
      double e = r[i];
      for (int j = 0; j < k; ++j) e -= LA_(i, j) * s.alpha_c[j];
      s.eta[i] = e;
    }
    if (contacts) s.f.noalias() = p.Ht.transpose() * s.eta;
    else s.f = s.eta;
    s.ok = true;
    if (!with_qdd) return;
    // θ'' = M⁻¹ (τ − h − J̃ᵀ η) = L⁻ᵀ D⁻¹ (y − Y η).
    s.qdd.resize(n);
    for (int i = 0; i < n; ++i) {
      double a = y[i];
      for (int j = 0; j < m; ++j) a -= Y_(i, j) * s.eta[j];
      s.qdd[i] = a;
    }
    chol_M_.scale(s.qdd);
    chol_M_.backward(s.qdd);
    s.ok = true;
  }

 private:
  // factorLocked's solve: θ''_L from the rows, θ''_F by one substitution, η from the locked rows of M.
  // (θ'' is part of η's cost: always computed.)
  template <class Problem, class Solution>
  void solveLocked(const Problem& p, Solution& s) const {
    const int n = this->n(), m = this->m();
    // The locked accelerations θ''_c = σ b (b as the Schur route's bias), and (τ − h)_F − M_FL θ''_L.
    s.qdd.resize(n);
    for (int i = 0; i < n; ++i) s.qdd[i] = p.tau[i] - p.h[i];
    double locked[kLockCap];
    for (int r = 0; r < m; ++r) {
      double b = p.Jdot_qd[r];
      if (p.Adot_vc.size()) b -= p.Adot_vc[r];
      if (p.Hdot_w.size()) b += p.Hdot_w[r];
      if (p.stab.size()) b -= p.stab[r];
      locked[r] = sign_[r] * b;
      for (int i = 0; i < n; ++i) s.qdd[i] -= Mcol_(i, r) * locked[r];
    }
    // A locked entry meets only zeros of L on its way (its value never reaches a free coordinate); zero,
    // so that not even a non-finite one could (0 · ∞).
    for (int r = 0; r < m; ++r) s.qdd[coordinate_[r]] = 0.0;
    chol_M_.solveInPlace(s.qdd);
    for (int r = 0; r < m; ++r) s.qdd[coordinate_[r]] = locked[r];
    // η_r = σ_r (M_c· θ'' + h_c − τ_c).
    s.eta.resize(m);
    for (int r = 0; r < m; ++r) {
      const int c = coordinate_[r];
      double x = 0.0;
      for (int i = 0; i < n; ++i) x += Mcol_(i, r) * s.qdd[i];
      s.eta[r] = sign_[r] * (x + p.h[c] - p.tau[c]);
    }
    s.alpha_c.resize(0);
    s.f = s.eta;
    s.ok = true;
  }

  // factorLocked's matrix: M with the locked coordinates' rows and columns the identity's times `largest`.
  static constexpr int kCap = Nj == Eigen::Dynamic ? kMaxDof : (Nj > 0 ? Nj : 1);
  template <class Mat>
  struct LockedInertia {
    const Mat& M;
    const bool* locked;
    double largest;
    double operator()(int i, int j) const { return locked[i] || locked[j] ? (i == j ? largest : 0.0) : M(i, j); }
    Eigen::Index rows() const { return M.rows(); }
  };

  int n() const { return Nj == Eigen::Dynamic ? n_ : Nj; }
  int m() const { return Nr == Eigen::Dynamic ? m_ : Nr; }
  int k() const { return Nl == Eigen::Dynamic ? k_ : Nl; }
  int n_ = 0, m_ = 0, k_ = 0;
  CholeskyN<Nj> chol_M_;
  CholeskyN<Nr> chol_L_;
  CholeskyN<Nl> chol_S_;
  MatRC<Nj, Nr> Y_;       // L⁻¹ J̃ᵀ
  MatRC<Nr, Nl> A_, LA_;  // Ã and Λ⁻¹ Ã
  // factorLocked's rows: their coordinates and signs, and M's columns there (n × m).
  static constexpr int kLockCap = Nr == Eigen::Dynamic ? kMaxDof : (Nr > 0 ? Nr : 1);
  bool locked_ = false;
  int coordinate_[kLockCap] = {};
  double sign_[kLockCap] = {};
  MatRC<Nj, Nr> Mcol_;
};

// The block LU's answer at fixed sizes (the fallback near singular configurations).
template <int Nj, int Nr, int Nl>
ConstrainedSolutionT<Nj, Nr, Nl> solveConstrainedBlockLU(const ConstrainedProblemT<Nj, Nr, Nl>& p) {
  if constexpr (Nj == Eigen::Dynamic && Nr == Eigen::Dynamic && Nl == Eigen::Dynamic) {
    return solveConstrainedBlockLU(p);
  } else {
    constexpr int D = Eigen::Dynamic;
    return withSizes<Nj, Nr, Nl>(solveConstrainedBlockLU(withSizes<D, D, D>(p)));
  }
}

template <int Nj, int Nr, int Nl>
ConstrainedSolutionT<Nj, Nr, Nl> solveConstrained(const ConstrainedProblemT<Nj, Nr, Nl>& p) {
  ConstrainedSolutionT<Nj, Nr, Nl> s;
  if (p.Ht.size() > 0) {
    ConstrainedFactorT<Nj, Eigen::Dynamic, Nl> f;  // the contact rows H̃ J, H̃ A
    if (!f.factor(p, MatN(p.Ht * p.J), MatN(p.Ht * p.A))) return solveConstrainedBlockLU(p);
    f.solve(p, s);
  } else {
    ConstrainedFactorT<Nj, Nr, Nl> f;
    if (!f.factor(p, p.J, p.A)) return solveConstrainedBlockLU(p);
    f.solve(p, s);
  }
  return s;
}

}  // namespace dyn
