// Eq. (2) with rows that lock coordinates (physics/constrained_solve.h factorLocked: J̃ row i = −σ_i e_cᵢᵀ,
// joint limits at their stops) solved by elimination,
//   θ''_c = σ b,   M_FF θ''_F = (τ − h)_F − M_FL θ''_L,   η_i = σ_i (M_cᵢ· θ'' + h_cᵢ − τ_cᵢ),
// against the Schur-complement route on the same rows (factor(): Λ = J̃ M⁻¹ J̃ᵀ), on random M with
// several locked rows of either sign, with and without a Baumgarte term and a bias J'θ'; the sign of η
// (≥ 0: the stop pushes) where the answer is known in closed form; the fixed-size solve (six joints, as
// the PUMA's engine) bit for bit as the bounded one; the in-place factor as the factor of a modified copy;
// and a singular M_FF refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "physics/constrained_solve.h"

using namespace dyn;

namespace {

struct Random {
  std::mt19937_64 rng{43};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  double operator()() { return u(rng); }
  MatN spd(int n) {
    MatN B(n, n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) B(i, j) = u(rng);
    return B * B.transpose() + 0.3 * MatN::Identity(n, n);
  }
  VecN vec(int n) {
    VecN x(n);
    for (int i = 0; i < n; ++i) x[i] = u(rng);
    return x;
  }
};

// m distinct coordinates of n, and a sign for each.
void lockRows(Random& r, int n, int m, std::vector<int>& coordinate, std::vector<double>& sign) {
  std::vector<int> all(static_cast<std::size_t>(n));
  std::iota(all.begin(), all.end(), 0);
  std::shuffle(all.begin(), all.end(), r.rng);
  coordinate.assign(all.begin(), all.begin() + m);
  sign.clear();
  for (int i = 0; i < m; ++i) sign.push_back(r() < 0 ? -1.0 : 1.0);
}

// The problem with J̃ row i = −σ_i e_cᵢᵀ and no payload.
ConstrainedProblem lockedProblem(Random& r, int n, const std::vector<int>& coordinate, const std::vector<double>& sign, bool stab) {
  const int m = int(coordinate.size());
  ConstrainedProblem p;
  p.M = r.spd(n);
  p.tau = 10.0 * r.vec(n);
  p.h = 10.0 * r.vec(n);
  p.J = MatN::Zero(m, n);
  for (int i = 0; i < m; ++i) p.J(i, coordinate[std::size_t(i)]) = -sign[std::size_t(i)];
  p.A = MatN::Zero(m, 0);
  p.Jdot_qd = r.vec(m);
  if (stab) p.stab = 5.0 * r.vec(m);
  return p;
}

double relative(const VecN& a, const VecN& b) { return (a - b).norm() / std::max(1.0, b.norm()); }

}  // namespace

TEST_CASE("locked coordinates by elimination: the same θ'' and η as the Schur-complement solve") {
  Random r;
  int cases = 0;
  for (int n = 2; n <= 12; ++n)
    for (int m = 1; m < n; ++m)
      for (bool stab : {false, true}) {
        std::vector<int> coordinate;
        std::vector<double> sign;
        lockRows(r, n, m, coordinate, sign);
        const ConstrainedProblem p = lockedProblem(r, n, coordinate, sign, stab);
        ConstrainedFactorT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic> schur, locked;
        REQUIRE(schur.factor(p, p.J, p.A));
        REQUIRE(locked.factorLocked(p, coordinate.data(), sign.data(), m));
        ConstrainedSolution a, b;
        schur.solve(p, a);
        locked.solve(p, b);
        INFO("n = " << n << ", m = " << m << ", stab = " << stab);
        CHECK(relative(b.qdd, a.qdd) < 1e-12);
        CHECK(relative(b.eta, a.eta) < 1e-12);
        CHECK(VecN(b.f) == VecN(b.eta));
        // The rows hold: J̃ θ'' + J'θ' − s = 0, θ''_c = σ (J'θ' − s) exactly.
        for (int i = 0; i < m; ++i) {
          const double bias = p.Jdot_qd[i] - (stab ? p.stab[i] : 0.0);
          CHECK(b.qdd[coordinate[std::size_t(i)]] == sign[std::size_t(i)] * bias);
        }
        // And the equations of motion: M θ'' + h − τ = −J̃ᵀ η.
        CHECK((p.M * b.qdd + p.h - p.tau + p.J.transpose() * b.eta).norm() < 1e-11 * (1.0 + p.tau.norm() + p.h.norm()));
        // η alone (the lift-off check's solve) is the same η.
        ConstrainedSolution c;
        locked.solve(p, c, false);
        CHECK(VecN(c.eta) == VecN(b.eta));
        ++cases;
      }
  CHECK(cases == 2 * 66);
}

TEST_CASE("locked coordinates: η presses (≥ 0) when the load drives the joint into its stop, pulls when away") {
  // M diagonal and no bias: the locked joint's η is σ (h_c − τ_c), the load it carries, and the others move freely.
  for (double sigma : {1.0, -1.0})      // lower stop (σ = +1), upper stop (σ = −1)
    for (double into : {1.0, -1.0}) {   // the load toward the stop, or away from it
      ConstrainedProblem p;
      p.M = MatN::Zero(3, 3);
      p.M.diagonal() << 2.0, 3.0, 4.0;
      p.M(0, 2) = p.M(2, 0) = 0.5;  // couples the free joints only
      p.h = VecN::Zero(3);
      p.tau = VecN::Zero(3);
      p.tau[1] = -sigma * into * 7.0;  // σ = +1 and into: pushes θ_1 down onto its lower stop
      p.tau[0] = 1.0;
      p.J = MatN::Zero(1, 3);
      p.J(0, 1) = -sigma;
      p.A = MatN::Zero(1, 0);
      p.Jdot_qd = VecN::Zero(1);
      const int coordinate = 1;
      ConstrainedFactorT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic> f;
      REQUIRE(f.factorLocked(p, &coordinate, &sigma, 1));
      ConstrainedSolution s;
      f.solve(p, s);
      INFO("σ = " << sigma << ", into = " << into);
      CHECK(s.eta[0] == doctest::Approx(into * 7.0));
      CHECK(s.qdd[1] == 0.0);
      // The free joints 0 and 2 as M_FF alone solves them: [2 .5; .5 4] x = (1, 0).
      CHECK(s.qdd[0] == doctest::Approx(4.0 / 7.75));
      CHECK(s.qdd[2] == doctest::Approx(-0.5 / 7.75));
    }
}

TEST_CASE("locked coordinates: six joints fixed (the PUMA's engine) solve bit for bit as bounded sizes") {
  Random r;
  for (int m = 0; m <= 5; ++m)
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<int> coordinate;
      std::vector<double> sign;
      lockRows(r, 6, m, coordinate, sign);
      const ConstrainedProblem p = lockedProblem(r, 6, coordinate, sign, trial % 2 == 0);
      ConstrainedFactorT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic> bounded;
      ConstrainedFactorT<6, Eigen::Dynamic, 0> fixed;
      ConstrainedProblemT<6, Eigen::Dynamic, 0> q;
      q.M = p.M, q.tau = p.tau, q.h = p.h, q.J = p.J, q.A.resize(m, 0), q.Jdot_qd = p.Jdot_qd, q.stab = p.stab;
      REQUIRE(bounded.factorLocked(p, coordinate.data(), sign.data(), m));
      REQUIRE(fixed.factorLocked(q, coordinate.data(), sign.data(), m));
      ConstrainedSolution a;
      ConstrainedSolutionT<6, Eigen::Dynamic, 0> b;
      bounded.solve(p, a);
      fixed.solve(q, b);
      CHECK(VecN(b.qdd) == VecN(a.qdd));
      CHECK(VecN(b.eta) == VecN(a.eta));
      if (m == 0) {  // nothing locked: M's own Cholesky solve, as the Schur route without rows
        ConstrainedFactorT<6, Eigen::Dynamic, 0> plain;
        REQUIRE(plain.factor(q, q.J, q.A));
        ConstrainedSolutionT<6, Eigen::Dynamic, 0> c;
        plain.solve(q, c);
        CHECK(VecN(c.qdd) == VecN(b.qdd));
      }
    }
}

TEST_CASE("locked coordinates: a singular M_FF is refused (the caller's pivoted LU decides)") {
  // Coordinates 0 and 1 move as one (equal columns in M): with 2 locked, M_FF = [1 1; 1 1] is singular;
  // with 0 locked, M_FF = [1 0; 0 2] is not.
  ConstrainedProblem p;
  p.M = MatN::Zero(3, 3);
  p.M << 1, 1, 0, 1, 1, 0, 0, 0, 2;
  const int two = 2, zero = 0;
  const double sign = 1.0;
  ConstrainedFactorT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic> f;
  CHECK_FALSE(f.factorLocked(p, &two, &sign, 1));
  CHECK(f.factorLocked(p, &zero, &sign, 1));
}

TEST_CASE("locked coordinates: M_FF's factor read in place is the factor of M with the locked rows replaced, bit for bit") {
  // factorLocked reads M through a view (no copy): the solve must be the one a Cholesky of the modified
  // copy gives, M with each locked coordinate's row and column the identity's times M's largest diagonal entry.
  Random r;
  for (int n = 2; n <= 8; ++n)
    for (int m = 1; m < n; ++m) {
      std::vector<int> coordinate;
      std::vector<double> sign;
      lockRows(r, n, m, coordinate, sign);
      const ConstrainedProblem p = lockedProblem(r, n, coordinate, sign, true);
      ConstrainedFactorT<Eigen::Dynamic, Eigen::Dynamic, Eigen::Dynamic> f;
      REQUIRE(f.factorLocked(p, coordinate.data(), sign.data(), m));
      ConstrainedSolution s;
      f.solve(p, s);
      // The same steps written on the copy.
      MatN M = p.M;
      const double largest = p.M.diagonal().cwiseAbs().maxCoeff();
      VecN x = p.tau - p.h;
      std::vector<double> locked;
      for (int i = 0; i < m; ++i) {
        const int c = coordinate[std::size_t(i)];
        locked.push_back(sign[std::size_t(i)] * (p.Jdot_qd[i] - p.stab[i]));
        for (int j = 0; j < n; ++j) x[j] -= p.M(j, c) * locked.back();
      }
      for (int i = 0; i < m; ++i) {
        const int c = coordinate[std::size_t(i)];
        M.row(c).setZero(), M.col(c).setZero(), M(c, c) = largest;
        x[c] = 0.0;
      }
      CholeskyN<> copy;
      REQUIRE(copy.compute(M));
      copy.solveInPlace(x);
      for (int i = 0; i < m; ++i) x[coordinate[std::size_t(i)]] = locked[std::size_t(i)];
      INFO("n = " << n << ", m = " << m);
      CHECK(VecN(s.qdd) == x);
    }
}
