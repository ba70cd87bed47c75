// The generic constrained solve, eqs. (2)/(3), against an independent reference: the KKT
// (Lagrange multiplier) system of the whole mechanism, [W Gᵀ; G 0][a; λ] = [Q; −Ġv].
#include <doctest/doctest.h>

#include <Eigen/LU>

#include "physics/constrained.h"
#include "tests/physics/arms.h"

using namespace dyn;

namespace {

struct Setup {
  TreeModel<Planar> model = test::planarArm();
  TreeData<Planar> data{model};
  VecN q{3}, qd{3}, tau{3};
  ConstrainedProblem p;
  Setup(double load_mass) {
    q << 0.5, -1.2, 0.7;
    qd << 0.8, -0.3, 1.1;
    tau << 0.7, -0.4, 0.2;
    forwardKinematics(model, q, qd, data);
    p.M = crba(model, data);
    p.h = rnea(model, data, qd, VecN::Zero(3));
    p.tau = tau;
    pointJacobian(model, data, 2, Planar::Pos(0.2, 0.0), p.J, p.Jdot_qd);
    p.A = Eigen::Vector3d(0, 1, 0);  // the tip may slide along world x
    p.Mc = MatN::Constant(1, 1, load_mass);
  }
};

}  // namespace

TEST_CASE("eq. (2) agrees with the KKT system of the whole mechanism") {
  Setup s(0.5);
  const ConstrainedSolution sol = solveConstrained(s.p);
  REQUIRE(sol.ok);
  // KKT on (θ, x_c): W = diag(M, m_c), G = [J, −A], Ġ v = J'θ' (A constant).
  MatN K = MatN::Zero(7, 7);
  K.topLeftCorner(3, 3) = s.p.M;
  K(3, 3) = 0.5;
  MatN G(3, 4);
  G << s.p.J, -s.p.A;
  K.block(0, 4, 4, 3) = G.transpose();
  K.block(4, 0, 3, 4) = G;
  VecN rhs(7);
  rhs << s.tau - s.p.h, 0.0, -s.p.Jdot_qd;
  const VecN x = K.fullPivLu().solve(rhs);
  CHECK((sol.qdd - x.head(3)).norm() < 1e-10);
  CHECK(std::abs(sol.alpha_c[0] - x[3]) < 1e-10);
  // The multiplier is the force the arm applies (M θ'' = τ − h − Jᵀ f ⇒ λ = f).
  CHECK((sol.f - x.tail(3)).norm() < 1e-9);
  // The solution satisfies the acceleration constraint and the load's equation.
  CHECK((s.p.J * sol.qdd + s.p.Jdot_qd - s.p.A * sol.alpha_c).norm() < 1e-10);
  CHECK(std::abs(0.5 * sol.alpha_c[0] - sol.f[1]) < 1e-10);
}

TEST_CASE("load inside the arm (M_c = 0): the constraint force does no work along the free motion") {
  Setup s(0.0);
  s.p.Mc = MatN::Zero(1, 1);
  const ConstrainedSolution sol = solveConstrained(s.p);
  REQUIRE(sol.ok);
  CHECK(std::abs((s.p.A.transpose() * sol.f)(0)) < 1e-10);  // Aᵀ f = 0
  // Power of the constraint force on the arm along any motion that satisfies Jθ' = A v_c.
  const double v_c = 0.37;
  const VecN qd_free = s.p.J.fullPivLu().solve(VecN(s.p.A * v_c));
  CHECK(std::abs(sol.f.dot(s.p.J * qd_free)) < 1e-10);
}

TEST_CASE("eq. (3) with a free rotation H = (1,0,0) equals eq. (2) on the remaining rows") {
  Setup s(0.5);
  ConstrainedProblem with_h = s.p;
  with_h.Ht = (MatN(2, 3) << 0, 1, 0, 0, 0, 1).finished();
  with_h.Hdot_w = VecN::Zero(3);  // H constant: H'w = 0
  const ConstrainedSolution a = solveConstrained(with_h);
  // Eq. (2) with only the x and y rows of J.
  ConstrainedProblem reduced = s.p;
  reduced.J = s.p.J.bottomRows(2);
  reduced.Jdot_qd = s.p.Jdot_qd.tail(2);
  reduced.A = s.p.A.bottomRows(2);
  const ConstrainedSolution b = solveConstrained(reduced);
  REQUIRE(a.ok);
  REQUIRE(b.ok);
  CHECK((a.qdd - b.qdd).norm() < 1e-10);
  CHECK((a.eta - b.f).norm() < 1e-10);
  CHECK(std::abs(a.f[0]) < 1e-14);  // no moment through a point contact
}

TEST_CASE("direct force control: F in N(Aᵀ) shifts f by F and leaves α_c untouched") {
  Setup s(0.5);
  const ConstrainedSolution base = solveConstrained(s.p);
  const Eigen::Vector3d F(0.3, 0.0, -2.0);  // Aᵀ F = 0
  s.p.tau += s.p.J.transpose() * F;
  const ConstrainedSolution pushed = solveConstrained(s.p);
  CHECK(std::abs(pushed.alpha_c[0] - base.alpha_c[0]) < 1e-10);
  CHECK((pushed.f - base.f - F).norm() < 1e-9);
}

TEST_CASE("Baumgarte term enters the acceleration row") {
  Setup s(0.5);
  ConstrainedProblem p = s.p;
  p.stab = VecN::Constant(3, 0.1);
  const ConstrainedSolution sol = solveConstrained(p);
  // J θ'' + J'θ' − A α_c = s
  CHECK((s.p.J * sol.qdd + s.p.Jdot_qd - s.p.A * sol.alpha_c - p.stab).norm() < 1e-10);
}
