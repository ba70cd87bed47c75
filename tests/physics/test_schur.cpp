// The fast paths of the physics against their references: the small Cholesky (cholesky.h)
// against Eigen's LLT, and the Schur-complement solve of eqs. (2)/(3) against the full-pivot LU
// of the whole block matrix, on random problems of many shapes, and near singular ones; the
// fixed-size solve (ConstrainedProblemT<n, m, k>) against the bounded-size one.
#include <doctest/doctest.h>

#include <Eigen/Cholesky>
#include <random>

#include "physics/cholesky.h"
#include "physics/constrained_solve.h"

using namespace dyn;

namespace {

struct Random {
  std::mt19937_64 rng{7};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  MatN mat(int r, int c) {
    MatN m(r, c);
    for (int j = 0; j < c; ++j)
      for (int i = 0; i < r; ++i) m(i, j) = u(rng);
    return m;
  }
  VecN vec(int n) { return mat(n, 1).col(0); }
  MatN spd(int n) {
    const MatN B = mat(n, n);
    return B * B.transpose() + 0.5 * MatN::Identity(n, n);
  }
};

double relativeDifference(const VecN& a, const VecN& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

}  // namespace

TEST_CASE("Cholesky L D Lᵀ: solves and inner products agree with Eigen's LLT") {
  Random r;
  for (int n = 1; n <= kMaxDof; ++n) {
    const MatN A = r.spd(n);
    Cholesky c;
    REQUIRE(c.compute(A));
    const Eigen::LLT<MatN> llt(A);
    // A⁻¹ X for several right-hand sides at once.
    MatN X = r.mat(n, 3);
    const MatN ref = llt.solve(X);
    c.solveInPlace(X);
    CHECK((X - ref).norm() / ref.norm() < 1e-11);
    // Bᵀ A⁻¹ B from the forward-substituted B.
    const MatN B = r.mat(n, 4);
    MatN Y = B, G(4, 4);
    c.forward(Y);
    c.inner(Y, 4, G);
    const MatN Gref = B.transpose() * llt.solve(B);
    CHECK((G - Gref).norm() / Gref.norm() < 1e-11);
  }
}

TEST_CASE("Cholesky refuses singular, indefinite and non-finite matrices") {
  Random r;
  Cholesky c;
  const MatN B = r.mat(4, 3);
  CHECK_FALSE(c.compute(MatN(B * B.transpose())));  // rank 3 of 4
  MatN indefinite = r.spd(3);
  indefinite(2, 2) = -1.0;
  CHECK_FALSE(c.compute(indefinite));
  MatN nan = r.spd(3);
  nan(1, 1) = std::nan("");
  CHECK_FALSE(c.compute(nan));
  CHECK(c.compute(r.spd(3)));
}

TEST_CASE("Schur-complement solve equals the block LU on random problems of every kind") {
  Random r;
  int cases = 0;
  for (int n = 1; n <= 8; ++n)
    for (int m = 1; m <= n; ++m)
      for (int k = 0; k <= m; ++k)
        for (int variant = 0; variant < 4; ++variant) {
          ConstrainedProblem p;
          p.M = r.spd(n);
          p.h = r.vec(n);
          p.tau = r.vec(n);
          p.J = r.mat(m, n);
          p.Jdot_qd = r.vec(m);
          p.A = r.mat(m, k);
          // 0: load inside the arm (M_c = 0); 1: load with its own dynamics; 2: + A'v_c, Baumgarte;
          // 3: contacts, eq. (3), with H̃ keeping m − 1 directions.
          p.Mc = variant == 0 ? MatN(MatN::Zero(k, k)) : r.spd(k);
          if (variant >= 1) p.bc_Gc = r.vec(k);
          if (variant == 2) {
            p.Adot_vc = r.vec(m);
            p.stab = r.vec(m);
          }
          if (variant == 3) {
            if (m < 2 || k > m - 1) continue;
            p.Ht = r.mat(m - 1, m);
            p.Hdot_w = r.vec(m);
          }
          const ConstrainedSolution a = solveConstrained(p), b = solveConstrainedBlockLU(p);
          REQUIRE(a.ok);
          REQUIRE(b.ok);
          CHECK(relativeDifference(a.qdd, b.qdd) < 1e-9);
          CHECK(relativeDifference(a.f, b.f) < 1e-9);
          CHECK(relativeDifference(a.eta, b.eta) < 1e-9);
          if (k > 0) CHECK(relativeDifference(a.alpha_c, b.alpha_c) < 1e-9);
          ++cases;
        }
  CHECK(cases > 300);
}

TEST_CASE("near singular problems go to the pivoted LU: solved when the block matrix is regular") {
  Random r;
  ConstrainedProblem p;
  p.M = r.spd(3);
  p.h = r.vec(3);
  p.tau = r.vec(3);
  p.J = r.mat(3, 3);
  p.J.row(2).setZero();  // the arm cannot move this row: Λ is singular
  p.Jdot_qd = r.vec(3);
  p.A = Eigen::Vector3d(0.3, -0.2, 1.0);  // but the payload can
  p.Mc = MatN::Constant(1, 1, 0.5);
  SUBCASE("Λ singular, block matrix regular: a valid solution") {
    const ConstrainedSolution s = solveConstrained(p);
    REQUIRE(s.ok);
    // Both rows of eq. (2) hold: M_c α_c = Aᵀ f and J θ'' + J'θ' = A α_c, with M θ'' = τ − h − Jᵀ f.
    CHECK(std::abs(0.5 * s.alpha_c[0] - p.A.col(0).dot(s.f)) < 1e-9);
    CHECK((p.J * s.qdd + p.Jdot_qd - p.A * s.alpha_c).norm() < 1e-9);
    CHECK((p.M * s.qdd - (p.tau - p.h - p.J.transpose() * s.f)).norm() < 1e-9);
  }
  SUBCASE("a free direction neither the arm nor the payload can take: reported, not thrown") {
    p.A(2, 0) = 0.0;
    CHECK_FALSE(solveConstrained(p).ok);
  }
  SUBCASE("M not positive definite: reported") {
    p.J = r.mat(3, 3);
    p.M(1, 1) = -1.0;
    CHECK_FALSE(solveConstrained(p).ok);
  }
}

namespace {

template <int N, int M, int K>
void checkFixedMatchesBounded(Random& r, int variant) {
  ConstrainedProblem p;
  p.M = r.spd(N);
  p.h = r.vec(N);
  p.tau = r.vec(N);
  p.J = r.mat(M, N);
  p.Jdot_qd = r.vec(M);
  p.A = r.mat(M, K);
  p.Mc = r.spd(K);
  p.bc_Gc = r.vec(K);
  if (variant == 1) p.stab = r.vec(M);
  if (variant == 2) {
    p.Ht = r.mat(M - 1, M);  // contacts, eq. (3)
    p.Hdot_w = r.vec(M);
  }
  if (variant == 3) p.J.row(0).setZero();  // Λ singular: the fixed solve falls back to the LU too
  // The same problem at compile-time sizes (constrained.h's copy: checked here too, since b solves p as given).
  const auto a = solveConstrained(withSizes<N, M, K>(p));
  const ConstrainedSolution b = solveConstrained(p);
  REQUIRE(a.ok == b.ok);
  REQUIRE(a.ok);
  CHECK(relativeDifference(VecN(a.qdd), b.qdd) < 1e-12);
  CHECK(relativeDifference(VecN(a.f), b.f) < 1e-12);
  CHECK(relativeDifference(VecN(a.eta), b.eta) < 1e-12);
  CHECK(relativeDifference(VecN(a.alpha_c), b.alpha_c) < 1e-12);
}

}  // namespace

TEST_CASE("fixed-size solve equals the bounded-size one (eq. 2, Baumgarte, contacts, singular Λ)") {
  Random r;
  for (int variant = 0; variant < 4; ++variant) {
    CAPTURE(variant);
    checkFixedMatchesBounded<3, 3, 1>(r, variant);  // the slider crank
    checkFixedMatchesBounded<6, 4, 2>(r, variant);
    checkFixedMatchesBounded<2, 2, 1>(r, variant);
  }
}
