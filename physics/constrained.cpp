// Eqs. (2)/(3) for any sizes up to kMaxDof: the Schur route (constrained_solve.h) instantiated
// for bounded sizes, and the full-pivot LU of the block matrix it falls back to:
//   [ M_c   −Ãᵀ ] [ α_c ]   [ −b_c − G_c ]
//   [ Ã      Λ  ] [  η  ] = [  r         ]     Λ = J̃ M⁻¹ J̃ᵀ,  r as in constrained_solve.h
#include "physics/constrained.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "physics/constrained_solve.h"

namespace dyn {
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
  if (p.compliance.size()) K.bottomRightCorner(r, r).diagonal() += p.compliance;
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

template ConstrainedSolution solveConstrained(const ConstrainedProblem&);

}  // namespace dyn
