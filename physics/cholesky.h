// Square-root-free Cholesky of a small symmetric positive definite matrix (Golub & Van Loan §4.1):
//     A = L D Lᵀ,   L unit lower triangular, D diagonal > 0
//     A⁻¹ x = L⁻ᵀ D⁻¹ L⁻¹ x          (forward substitution, scaling, back substitution)
//     Bᵀ A⁻¹ B = Yᵀ D⁻¹ Y   with Y = L⁻¹ B                 (e.g. Λ = J M⁻¹ Jᵀ)
// Used for M, Λ and the projection metrics. Plain loops over the bounded sizes of types.h: on the
// 1×1 … 24×24 matrices of the labs they cost a fraction of Eigen's dynamic-size LLT/LDLT, whose
// generic paths (blocking, BLAS-like kernels, pivoting) outweigh the arithmetic of a 3×3.
// No pivoting, so a pivot that is not clearly positive (≤ 1e-12 × the largest diagonal entry) is
// refused: the caller then falls back to a pivoted LU, which judges whether A is singular.
#pragma once
#include <algorithm>
#include <cmath>

#include "physics/types.h"

namespace dyn {

class Cholesky {
 public:
  // Factors A, or the leading square block of A (only its lower triangle is read).
  // False if it is not clearly positive definite.
  template <class Mat>
  bool compute(const Mat& A) {
    n_ = int(A.rows());
    double largest = 0;
    for (int i = 0; i < n_; ++i) largest = std::max(largest, std::abs(A(i, i)));
    for (int j = 0; j < n_; ++j) {
      // Row j of L, l_jk = (a_jk − Σ_{i<k} l_ji d_i l_ki) / d_k, then its pivot d_j.
      double d = A(j, j);
      for (int k = 0; k < j; ++k) {
        double ld = A(j, k);
        for (int i = 0; i < k; ++i) ld -= l(j, i) * l(k, i) * d_[i];
        l(j, k) = ld * dinv_[k];
        d -= l(j, k) * ld;  // pivot d_j = a_jj − Σ_k l_jk² d_k
      }
      if (!(d > 1e-12 * largest)) return false;  // also catches NaN
      d_[j] = d;
      dinv_[j] = 1.0 / d;
    }
    return true;
  }

  int size() const { return n_; }

  // X ← L⁻¹ X, column by column (X: VecN or MatN with size() rows).
  template <class X>
  void forward(X& x) const {
    for (int c = 0; c < int(x.cols()); ++c)
      for (int i = 1; i < n_; ++i) {
        double s = x(i, c);
        for (int k = 0; k < i; ++k) s -= l(i, k) * x(k, c);
        x(i, c) = s;
      }
  }
  // X ← L⁻ᵀ X.
  template <class X>
  void backward(X& x) const {
    for (int c = 0; c < int(x.cols()); ++c)
      for (int i = n_ - 2; i >= 0; --i) {
        double s = x(i, c);
        for (int k = i + 1; k < n_; ++k) s -= l(k, i) * x(k, c);
        x(i, c) = s;
      }
  }
  // X ← D⁻¹ X.
  template <class X>
  void scale(X& x) const {
    for (int c = 0; c < int(x.cols()); ++c)
      for (int i = 0; i < n_; ++i) x(i, c) *= dinv_[i];
  }
  // X ← A⁻¹ X.
  template <class X>
  void solveInPlace(X& x) const {
    forward(x);
    scale(x);
    backward(x);
  }
  // G = Yᵀ D⁻¹ Y (first `rows` rows) for Y = L⁻¹ B already forward-substituted: Bᵀ A⁻¹ B.
  void inner(const MatN& y, int rows, MatN& g) const {
    g.resize(rows, y.cols());
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < int(y.cols()); ++j) {
        double s = 0;
        for (int k = 0; k < n_; ++k) s += y(k, i) * dinv_[k] * y(k, j);
        g(i, j) = s;
      }
  }

 private:
  double& l(int i, int k) { return L_[i * kMaxDof + k]; }
  double l(int i, int k) const { return L_[i * kMaxDof + k]; }
  int n_ = 0;
  double L_[kMaxDof * kMaxDof];        // strictly lower triangle of L, row-major
  double d_[kMaxDof], dinv_[kMaxDof];  // D and D⁻¹
};

}  // namespace dyn
