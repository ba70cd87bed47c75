// Square-root-free Cholesky of a small symmetric positive definite matrix (Golub & Van Loan §4.1):
//     A = L D Lᵀ,   L unit lower triangular, D diagonal > 0
//     A⁻¹ x = L⁻ᵀ D⁻¹ L⁻¹ x          (forward substitution, scaling, back substitution)
//     Bᵀ A⁻¹ B = Yᵀ D⁻¹ Y   with Y = L⁻¹ B                 (e.g. Λ = J M⁻¹ Jᵀ)
// Used for M, Λ and the projection metrics. Plain loops: on the 1×1 … 24×24 matrices of the labs
// they cost a fraction of Eigen's dynamic-size LLT/LDLT, whose generic paths (blocking, BLAS-like
// kernels, pivoting) outweigh the arithmetic of a 3×3. With the size N known at compile time
// (a lab's own mechanism) the loops unroll completely; CholeskyN<> takes any size up to kMaxDof.
// No pivoting, so a pivot that is not clearly positive (≤ 1e-12 × the largest diagonal entry) is
// refused: the caller then falls back to a pivoted LU, which judges whether A is singular.
#pragma once
#include <algorithm>
#include <cmath>

#include "physics/types.h"

namespace dyn {

template <int N = Eigen::Dynamic>
class CholeskyN {
  static constexpr int kCap = N == Eigen::Dynamic ? kMaxDof : N;

 public:
  // Factors A, or the leading size×size block of A (only its lower triangle is read); with a
  // fixed N, the leading N×N block. False if it is not clearly positive definite.
  template <class Mat>
  bool compute(const Mat& A, int size = -1) {
    if constexpr (N == Eigen::Dynamic) n_ = size >= 0 ? size : int(A.rows());
    const int n = this->size();
    double largest = 0;
    for (int i = 0; i < n; ++i) largest = std::max(largest, std::abs(A(i, i)));
    for (int j = 0; j < n; ++j) {
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

  int size() const {
    if constexpr (N == Eigen::Dynamic) return n_;
    else return N;
  }

  // X ← L⁻¹ X, column by column (X: a vector or matrix with size() rows).
  template <class X>
  void forward(X& x) const {
    for (int c = 0; c < int(x.cols()); ++c)
      for (int i = 1; i < size(); ++i) {
        double s = x(i, c);
        for (int k = 0; k < i; ++k) s -= l(i, k) * x(k, c);
        x(i, c) = s;
      }
  }
  // X ← L⁻ᵀ X.
  template <class X>
  void backward(X& x) const {
    for (int c = 0; c < int(x.cols()); ++c)
      for (int i = size() - 2; i >= 0; --i) {
        double s = x(i, c);
        for (int k = i + 1; k < size(); ++k) s -= l(k, i) * x(k, c);
        x(i, c) = s;
      }
  }
  // X ← D⁻¹ X.
  template <class X>
  void scale(X& x) const {
    for (int c = 0; c < int(x.cols()); ++c)
      for (int i = 0; i < size(); ++i) x(i, c) *= dinv_[i];
  }
  // X ← A⁻¹ X.
  template <class X>
  void solveInPlace(X& x) const {
    forward(x);
    scale(x);
    backward(x);
  }
  // G = Yᵀ D⁻¹ Y (first `rows` columns of Y against all) for Y = L⁻¹ B already
  // forward-substituted: Bᵀ A⁻¹ B. G must already have rows × Y.cols() entries.
  template <class Y, class G>
  void inner(const Y& y, int rows, G& g) const {
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < int(y.cols()); ++j) {
        double s = 0;
        for (int k = 0; k < size(); ++k) s += y(k, i) * dinv_[k] * y(k, j);
        g(i, j) = s;
      }
  }
  // g = Yᵀ D⁻¹ y (first `rows` columns of Y) for Y = L⁻¹ B and y = L⁻¹ b: Bᵀ A⁻¹ b.
  template <class Y, class V, class G>
  void inner(const Y& Ym, int rows, const V& y, G& g) const {
    for (int i = 0; i < rows; ++i) {
      double s = 0;
      for (int k = 0; k < size(); ++k) s += Ym(k, i) * dinv_[k] * y[k];
      g[i] = s;
    }
  }

 private:
  double& l(int i, int k) { return L_[i * kCap + k]; }
  double l(int i, int k) const { return L_[i * kCap + k]; }
  int n_ = 0;                      // the size when N is dynamic
  double L_[kCap * kCap];          // strictly lower triangle of L, row-major
  double d_[kCap], dinv_[kCap];    // D and D⁻¹
};

using Cholesky = CholeskyN<>;

}  // namespace dyn
