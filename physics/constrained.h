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
#pragma once
#include <Eigen/Cholesky>

#include "physics/types.h"

namespace dyn {

struct ConstrainedProblem {
  // Tree at the current state (n joints).
  MatN M;          // n×n joint-space inertia
  VecN h;          // n: C θ' + G (+ K θ)
  VecN tau;        // n: joint torques
  // Constraint (m rows) and load (k free coordinates of the payload).
  MatN J;          // m×n
  VecN Jdot_qd;    // m: J'θ'
  MatN A;          // m×k
  VecN Adot_vc;    // m: A'v_c (empty: zero)
  MatN Mc;         // k×k (zero: load inside the arm)
  VecN bc_Gc;      // k: b_c + G_c (empty: zero)
  // Contacts (eq. 3): H̃ (r×m) and H'w (m); leave H̃ empty for eq. (2).
  MatN Ht;
  VecN Hdot_w;
  // Drift stabilisation s (m), e.g. Baumgarte −2ζω ψ' − ω² φ; empty: none.
  VecN stab;
};

struct ConstrainedSolution {
  VecN alpha_c;  // k: payload acceleration
  VecN eta;      // r: constraint force in the constrained directions (= f for eq. 2)
  VecN f;        // m: spatial constraint force the arm applies, f = H̃^T η
  VecN qdd;      // n: θ'' = M⁻¹ (τ − h − J^T f)
  bool ok = true;  // false when the block matrix is singular (reported, never thrown)
};

ConstrainedSolution solveConstrained(const ConstrainedProblem& p);

// The same solve by a full-pivot LU of the whole (k + r) block matrix: the reference the tests
// compare with, and solveConstrained's fallback near singular configurations.
ConstrainedSolution solveConstrainedBlockLU(const ConstrainedProblem& p);

}  // namespace dyn
