// The one generic constrained solve of the lecture, eqs. (2) and (3). Every lab goes through it.
//
// Tree:        M θ'' + h = τ − J^T f              (h = Cθ' + G [+ Kθ])
// Constraint:  J θ'' + J'θ' (+ H w' + H'w) = A α_c + A'v_c + s     (s: Baumgarte term, else 0)
// Load:        M_c α_c + b_c + G_c = A^T f        (M_c = 0: load counted inside the arm)
// Contacts:    f = H̃^T η  with H̃ H = 0 (rows of H̃ span the constrained directions)
//
//   [ M_c          −A^T H̃^T    ] [ α_c ]   [ −b_c − G_c                                     ]
//   [ H̃ A     H̃ J M⁻¹ J^T H̃^T  ] [  η  ] = [ H̃ (J M⁻¹ (τ − h) + J'θ' + H'w − A'v_c − s)     ]
//
// Without contacts H̃ = I and η = f: that is eq. (2). Returns α_c, η, f and θ'' together.
// Solved by the Schur complement (M, then Λ = H̃ J M⁻¹ Jᵀ H̃ᵀ, then M_c + Ãᵀ Λ⁻¹ Ã, each by
// Cholesky); when one of them is not positive definite, by a full-pivot LU of the block matrix.
//
// Sizes: Nj = n tree joints, Nr = m constraint rows, Nl = k payload coordinates. ConstrainedProblem
// takes any sizes up to kMaxDof; a lab that knows its sizes uses ConstrainedProblemT<n, m, k>, the same
// solve with every loop unrolled (as Eigen does for fixed sizes).
#pragma once
#include "physics/types.h"

namespace dyn {

// An R×C matrix: fixed when both are known, else bounded (by kMaxDof unless given): never on the heap.
template <int R, int C, int MaxR = (R == Eigen::Dynamic ? kMaxDof : R), int MaxC = (C == Eigen::Dynamic ? kMaxDof : C)>
using MatRC = Eigen::Matrix<double, R, C, (MaxR == 1 && MaxC != 1) ? Eigen::RowMajor : Eigen::ColMajor, MaxR, MaxC>;

template <int Nj, int Nr, int Nl>
struct ConstrainedProblemT {
  // Tree at the current state (n joints).
  MatRC<Nj, Nj> M;          // n×n joint-space inertia
  MatRC<Nj, 1> h;          // n: C θ' + G (+ K θ)
  MatRC<Nj, 1> tau;        // n: joint torques
  // Constraint (m rows) and load (k free coordinates of the payload).
  MatRC<Nr, Nj> J;          // m×n
  MatRC<Nr, 1> Jdot_qd;    // m: J'θ'
  MatRC<Nr, Nl> A;          // m×k
  VecN Adot_vc;           // m: A'v_c (empty: zero)
  MatN Mc;                // k×k (empty: zero, the load inside the arm)
  VecN bc_Gc;             // k: b_c + G_c (empty: zero)
  // Contacts (eq. 3): H̃ (r×m) and H'w (m); leave H̃ empty for eq. (2).
  MatN Ht;
  VecN Hdot_w;
  // Drift stabilisation s (m), e.g. Baumgarte −2ζω ψ' − ω² φ; empty: none.
  VecN stab;
  // Compliance C (r, per η row) added to Λ's diagonal: Λ η + Ã α_c = r becomes (Λ + C) η + ...; empty:
  // none. A released row (an open unilateral contact: its J, A and bias rows zero) has C = 1, so η = 0.
  VecN compliance;
};

template <int Nj, int Nr, int Nl>
struct ConstrainedSolutionT {
  MatRC<Nl, 1> alpha_c;  // k: payload acceleration
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Nr == Eigen::Dynamic ? kMaxDof : Nr, 1>
      eta;              // r: constraint force in the constrained directions (= f for eq. 2)
  MatRC<Nr, 1> f;        // m: spatial constraint force the arm applies, f = H̃^T η
  MatRC<Nj, 1> qdd;      // n: θ'' = M⁻¹ (τ − h − J^T f)
  bool ok = true;       // false when the block matrix is singular (reported, never thrown)
};

// A problem or a solution at other sizes (fixed as bounded, or back), field by field.
template <int ToNj, int ToNr, int ToNl, int Nj, int Nr, int Nl>
ConstrainedProblemT<ToNj, ToNr, ToNl> withSizes(const ConstrainedProblemT<Nj, Nr, Nl>& p) {
  return {p.M, p.h, p.tau, p.J, p.Jdot_qd, p.A, p.Adot_vc, p.Mc, p.bc_Gc, p.Ht, p.Hdot_w, p.stab, p.compliance};
}
template <int ToNj, int ToNr, int ToNl, int Nj, int Nr, int Nl>
ConstrainedSolutionT<ToNj, ToNr, ToNl> withSizes(const ConstrainedSolutionT<Nj, Nr, Nl>& s) {
  return {s.alpha_c, s.eta, s.f, s.qdd, s.ok};
}

using ConstrainedProblem = ConstrainedProblemT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic>;
using ConstrainedSolution = ConstrainedSolutionT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic>;

// The solve, for any sizes (fixed ones: include physics/constrained_solve.h, which defines it).
template <int Nj, int Nr, int Nl>
ConstrainedSolutionT<Nj, Nr, Nl> solveConstrained(const ConstrainedProblemT<Nj, Nr, Nl>& p);

// The same solve by a full-pivot LU of the whole (k + r) block matrix: the reference the tests
// compare with, and solveConstrained's fallback near singular configurations.
ConstrainedSolution solveConstrainedBlockLU(const ConstrainedProblem& p);

extern template ConstrainedSolution solveConstrained(const ConstrainedProblem&);

}  // namespace dyn
