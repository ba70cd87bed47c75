// Tree algorithms cross-checked against each other and against the Lagrangian:
// CRBA = RNEA columns, M SPD, ABA = M⁻¹(τ − h), Cθ'+G = d/dt ∂L/∂θ' − ∂L/∂θ by finite
// differences, J and J'θ' by finite differences, planar = spatial for a planar arm.
#include <doctest/doctest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <random>

#include "tests/physics/arms.h"

using namespace dyn;

namespace {

template <class S>
struct Fixture {
  TreeModel<S> model;
  TreeData<S> data;
  explicit Fixture(TreeModel<S> m) : model(std::move(m)), data(model) {}
  MatN M(const VecN& q) {
    forwardKinematics(model, q, VecN::Zero(q.size()), data);
    return crba(model, data);
  }
  VecN h(const VecN& q, const VecN& qd) {
    forwardKinematics(model, q, qd, data);
    return rnea(model, data, qd, VecN::Zero(q.size()));
  }
  double U(const VecN& q) {
    forwardKinematics(model, q, VecN::Zero(q.size()), data);
    return potentialEnergy(model, data);
  }
};

template <class S>
void checkTree(TreeModel<S> model) {
  Fixture<S> fx(std::move(model));
  const int n = fx.model.dof();
  VecN q(n), qd(n), qdd(n);
  q << 0.3, -0.7, 1.1;
  qd << 0.9, -1.3, 0.7;  // tip ω ≠ 0, so J'θ' exercises ω × v
  qdd << -0.2, 0.5, 1.7;

  const MatN M = fx.M(q);
  SUBCASE("CRBA equals RNEA columns, and M is symmetric positive definite") {
    forwardKinematics(fx.model, q, VecN::Zero(n), fx.data);
    const VecN g = rnea(fx.model, fx.data, VecN::Zero(n), VecN::Zero(n));
    for (int j = 0; j < n; ++j) {
      const VecN col = rnea(fx.model, fx.data, VecN::Zero(n), VecN::Unit(n, j)) - g;
      CHECK((col - M.col(j)).norm() < 1e-12);
    }
    CHECK((M - M.transpose()).norm() < 1e-14);
    const Eigen::SelfAdjointEigenSolver<MatN> eig(M);
    CHECK(eig.eigenvalues().minCoeff() > 0);
  }
  SUBCASE("RNEA is M qdd + h, and ABA inverts it") {
    const VecN h = fx.h(q, qd);
    forwardKinematics(fx.model, q, qd, fx.data);
    const VecN tau = rnea(fx.model, fx.data, qd, qdd);
    CHECK((tau - (M * qdd + h)).norm() < 1e-12);
    const VecN qdd_aba = aba(fx.model, fx.data, qd, tau);
    CHECK((qdd_aba - qdd).norm() < 1e-10);
  }
  SUBCASE("C qd + G matches the Lagrangian by finite differences") {
    // h = Ṁ θ' − ½ (θ'ᵀ ∂M/∂θ_i θ')_i + ∂U/∂θ, with ∂/∂θ by central differences.
    const double e = 1e-6;
    VecN Mdot_qd = VecN::Zero(n), dT = VecN::Zero(n), dU = VecN::Zero(n);
    for (int i = 0; i < n; ++i) {
      const VecN ei = VecN::Unit(n, i) * e;
      const MatN dM = (fx.M(q + ei) - fx.M(q - ei)) / (2 * e);
      Mdot_qd += dM * qd * qd[i];
      dT[i] = 0.5 * qd.dot(dM * qd);
      dU[i] = (fx.U(q + ei) - fx.U(q - ei)) / (2 * e);
    }
    const VecN lagrange = Mdot_qd - dT + dU;
    CHECK((fx.h(q, qd) - lagrange).norm() < 1e-6);
  }
  SUBCASE("kinetic energy is ½ qdᵀ M qd") {
    forwardKinematics(fx.model, q, qd, fx.data);
    CHECK(kineticEnergy(fx.model, fx.data) == doctest::Approx(0.5 * qd.dot(M * qd)).epsilon(1e-12));
  }
  SUBCASE("point Jacobian and J'θ' match finite differences of the point's motion") {
    const typename S::Pos p = S::Pos::Constant(0.05);
    auto pos = [&](const VecN& qq) {
      forwardKinematics(fx.model, qq, VecN::Zero(n), fx.data);
      return pointPosition(fx.data, n - 1, p);
    };
    auto vel = [&](const VecN& qq, const VecN& vv) {
      forwardKinematics(fx.model, qq, vv, fx.data);
      MatN J;
      VecN Jd;
      pointJacobian(fx.model, fx.data, n - 1, p, J, Jd);
      return VecN(J * vv);
    };
    forwardKinematics(fx.model, q, qd, fx.data);
    MatN J;
    VecN Jdot_qd;
    pointJacobian(fx.model, fx.data, n - 1, p, J, Jdot_qd);
    const double e = 1e-6;
    // Linear rows: d/dt of the point position.
    const VecN v = J * qd;
    // eval(): an Eigen expression held by auto would point into the two destroyed temporaries
    // (ASan: stack-use-after-scope).
    const auto dp = ((pos(q + e * qd) - pos(q - e * qd)) / (2 * e)).eval();
    CHECK((v.tail(dp.size()) - VecN(dp)).norm() < 1e-8);
    // J'θ' = d/dt (J θ') at fixed θ'' = 0: difference along the flow.
    const VecN Jdot_fd = (vel(q + e * qd, qd) - vel(q - e * qd, qd)) / (2 * e);
    CHECK((Jdot_qd - Jdot_fd).norm() < 1e-6);
  }
}

}  // namespace

TEST_CASE("planar tree algorithms") { checkTree(test::planarArm()); }
TEST_CASE("spatial tree algorithms") { checkTree(test::spatialArm()); }

TEST_CASE("a planar arm built with 6-vector algebra has the same M and h") {
  TreeModel<Planar> p = test::planarArm();
  TreeModel<Spatial> s;
  for (const auto& b : p.bodies) {
    double m;
    Planar::Pos c;
    Planar::massAndCom(b.inertia, m, c);
    const double Izz = b.inertia(0, 0) - m * c.squaredNorm();
    s.addBody(b.parent, JointType::Revolute, {0, 0, 1}, Spatial::translation({b.X_tree.r.x(), b.X_tree.r.y(), 0}),
              Spatial::inertia(m, {c.x(), c.y(), 0}, Eigen::Vector3d(1e-3, 1e-3, Izz).asDiagonal()));
  }
  s.gravity << 0, 0, 0, 0, -9.81, 0;
  Fixture<Planar> fp(p);
  Fixture<Spatial> fs(s);
  VecN q(3), qd(3);
  q << 0.4, 0.2, -1.0;
  qd << 1.0, -2.0, 0.5;
  CHECK((fp.M(q) - fs.M(q)).norm() < 1e-12);
  CHECK((fp.h(q, qd) - fs.h(q, qd)).norm() < 1e-12);
}

TEST_CASE("joint springs: K is tridiagonal and K θ is the gradient of P_K") {
  VecN k(3), q(3);
  k << 10, 20, 30;
  q << 0.1, -0.3, 0.2;
  const MatN K = springStiffnessMatrix(k);
  CHECK(K(0, 0) == 30);
  CHECK(K(0, 1) == -20);
  CHECK(K(2, 2) == 30);
  CHECK(K(0, 2) == 0);
  const double e = 1e-6;
  for (int i = 0; i < 3; ++i) {
    const VecN ei = VecN::Unit(3, i) * e;
    const double grad = (springEnergy(k, q + ei) - springEnergy(k, q - ei)) / (2 * e);
    CHECK(springTorque(k, q)[i] == doctest::Approx(grad).epsilon(1e-8));
  }
}

TEST_CASE("CRBA with massless carriers equals RNEA columns") {
  // Three prismatic carriers (one placement turned), a heading joint, and two massive leaves on a
  // branch: 2 of 6 bodies carry mass (the unicycle's kind of tree).
  using Pos = Spatial::Pos;
  TreeModel<Spatial> t;
  t.gravity << 0, 0, 0, 0, 0, -9.81;
  const Spatial::Mat none = Spatial::Mat::Zero();
  const Spatial::Transform turned{Eigen::AngleAxisd(0.4, Pos(1, 2, 3).normalized()).toRotationMatrix(), Pos(0.1, -0.2, 0.3)};
  int b = t.addBody(-1, JointType::Prismatic, Pos::UnitX(), Spatial::Transform(), none);
  b = t.addBody(b, JointType::Prismatic, Pos(0, 1, 1), turned, none);
  b = t.addBody(b, JointType::Prismatic, Pos::UnitZ(), Spatial::Transform(), none);
  const int hub = t.addBody(b, JointType::Revolute, Pos::UnitZ(), Spatial::Transform(), none);
  const Eigen::Matrix3d Ic = (Eigen::Matrix3d() << 0.02, 0.003, -0.001, 0.003, 0.01, 0.002, -0.001, 0.002, 0.015).finished();
  t.addBody(hub, JointType::Revolute, Pos::UnitY(), turned, Spatial::inertia(2.0, Pos(0.05, 0.01, -0.02), Ic));
  t.addBody(hub, JointType::Revolute, Pos(1, 0, 1), Spatial::Transform(), Spatial::inertia(0.7, Pos(0.2, 0, 0.1), 0.5 * Ic));
  TreeData<Spatial> data(t);
  const int n = t.dof();
  VecN q(n);
  q << 0.3, -0.7, 1.1, 0.5, -1.2, 2.0;
  forwardKinematics(t, q, VecN::Zero(n), data);
  const MatN M = crba(t, data);
  const VecN g = rnea(t, data, VecN::Zero(n), VecN::Zero(n));
  for (int j = 0; j < n; ++j) {
    const VecN col = rnea(t, data, VecN::Zero(n), VecN::Unit(n, j)) - g;
    CHECK((col - M.col(j)).norm() < 1e-12);
  }
  CHECK((M - M.transpose()).norm() == 0.0);
  // The two leaves are on separate branches: no inertia couples them.
  CHECK(M(4, 5) == 0.0);
}

// ---------------------------------------------------------------- chains of any size
namespace {

// A planar chain of n links with varied lengths, masses, centres of mass (off the link axis) and
// inertias, deterministic (a fixed-seed generator), as Eigen::VectorXd states: sizes beyond kMaxDof.
TreeModel<Planar> variedPlanarChain(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.5, 1.5);
  TreeModel<Planar> m;
  double previous = 0;
  for (int i = 0; i < n; ++i) {
    const double L = 0.2 * u(rng), mass = u(rng);
    m.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(Planar::Pos(previous, 0.0)),
              Planar::inertia(mass, Planar::Pos(0.5 * L, 0.02 * (u(rng) - 1.0)), mass * L * L / 12 * u(rng)));
    previous = L;
  }
  m.gravity << 0, 0, -9.81;
  return m;
}

// The same idea in space: revolute joints about varied unit axes, placements along varied offsets.
TreeModel<Spatial> variedSpatialChain(int n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  TreeModel<Spatial> m;
  for (int i = 0; i < n; ++i) {
    const Spatial::Pos axis = Spatial::Pos(u(rng), u(rng), 1.0).normalized();
    const Spatial::Pos offset = i == 0 ? Spatial::Pos::Zero() : Spatial::Pos(0.1, 0.02 * u(rng), 0.02 * u(rng));
    const Eigen::Matrix3d Ic = Eigen::Vector3d(1e-3 * (2 + u(rng)), 1e-3 * (2 + u(rng)), 1e-3 * (2 + u(rng))).asDiagonal();
    m.addBody(i - 1, JointType::Revolute, axis, Spatial::translation(offset),
              Spatial::inertia(0.5 + 0.2 * u(rng), Spatial::Pos(0.05, 0.01 * u(rng), 0.0), Ic));
  }
  m.gravity << 0, 0, 0, 0, 0, -9.81;
  return m;
}

// ABA's θ'' against the O(N³) route: M θ'' = τ − RNEA(θ, θ', 0), M by CRBA, solved by Cholesky.
// Both are backward stable, so they may differ by about cond(M) ε ‖θ''‖ (cond(M) of a long chain
// reaches 1e6–1e8): the tolerance is 100 cond(M) ε, relative to ‖θ''‖; a wrong ABA is off by O(1).
template <class S>
void abaEqualsCrbaSolve(const TreeModel<S>& model, std::mt19937& rng) {
  const int n = model.dof();
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q(n), qd(n), tau(n);
  for (int i = 0; i < n; ++i) q[i] = u(rng), qd[i] = u(rng), tau[i] = 5 * u(rng);
  TreeData<S> data(model);
  forwardKinematics(model, q, qd, data);
  Eigen::VectorXd h(n), qdd_aba(n);
  rnea(model, data, qd, Eigen::VectorXd::Zero(n), h);
  Eigen::MatrixXd M(n, n);
  crba(model, data, M);
  aba(model, data, qd, tau, qdd_aba);
  const Eigen::VectorXd qdd_crba = M.llt().solve(tau - h);
  const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M, Eigen::EigenvaluesOnly).eigenvalues();
  const double cond = eig.maxCoeff() / eig.minCoeff();
  const double rel = (qdd_aba - qdd_crba).norm() / qdd_crba.norm();
  INFO("n = " << n << ", cond(M) = " << cond << ", |Δθ''|/|θ''| = " << rel);
  CHECK(rel < 100 * cond * std::numeric_limits<double>::epsilon());
  // And RNEA of ABA's answer gives τ back (the output overloads write into plain vectors).
  Eigen::VectorXd tau_back(n);
  forwardKinematics(model, q, qd, data);
  rnea(model, data, qd, qdd_aba, tau_back);
  CHECK((tau_back - tau).norm() < 1e-6 * tau.norm());
}

// Total energy of a chain at (q, qd).
double energy(const TreeModel<Planar>& model, TreeData<Planar>& data, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  forwardKinematics(model, q, qd, data);
  return kineticEnergy(model, data) + potentialEnergy(model, data);
}

// |E(t) − E(0)| over `duration` of the passive chain under RK4 with ABA, relative to its kinetic energy at the end.
double rk4EnergyDrift(const TreeModel<Planar>& model, const Eigen::VectorXd& q0, const Eigen::VectorXd& qd0, double dt,
                      double duration, double* kinetic = nullptr) {
  const int n = model.dof();
  TreeData<Planar> data(model);
  const Eigen::VectorXd tau = Eigen::VectorXd::Zero(n);
  auto accel = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    Eigen::VectorXd a(n);
    forwardKinematics(model, q, qd, data);
    aba(model, data, qd, tau, a);
    return a;
  };
  Eigen::VectorXd q = q0, qd = qd0;
  const double E0 = energy(model, data, q, qd);
  double worst = 0;
  for (int k = 0; k < int(std::lround(duration / dt)); ++k) {
    const Eigen::VectorXd a1 = accel(q, qd), v1 = qd;
    const Eigen::VectorXd a2 = accel(q + 0.5 * dt * v1, qd + 0.5 * dt * a1), v2 = qd + 0.5 * dt * a1;
    const Eigen::VectorXd a3 = accel(q + 0.5 * dt * v2, qd + 0.5 * dt * a2), v3 = qd + 0.5 * dt * a2;
    const Eigen::VectorXd a4 = accel(q + dt * v3, qd + dt * a3), v4 = qd + dt * a3;
    q += dt / 6 * (v1 + 2 * v2 + 2 * v3 + v4);
    qd += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
    worst = std::max(worst, std::abs(energy(model, data, q, qd) - E0));
  }
  forwardKinematics(model, q, qd, data);
  if (kinetic) *kinetic = kineticEnergy(model, data);
  return worst;
}

}  // namespace

TEST_CASE("chains beyond kMaxDof: ABA equals the CRBA + Cholesky solve of τ − RNEA(θ'' = 0)") {
  std::mt19937 rng(13);
  for (int n : {50, 200}) abaEqualsCrbaSolve(variedPlanarChain(n, rng), rng);
  abaEqualsCrbaSolve(variedSpatialChain(50, rng), rng);
}

TEST_CASE("a free 100-link chain conserves energy under RK4 + ABA, converging at fourth order") {
  // The passive chain (τ = 0, gravity) from a bent, moving start, 0.1 s. RK4's energy error is
  // O(dt⁴): at dt = 1 ms it is a tiny fraction of the kinetic energy gained, and halving dt cuts it
  // about 16× (> 8 asserted). A wrong ABA (not the chain's M⁻¹) breaks both.
  const TreeModel<Planar> chain = uniformPlanarChain(100, 0.05, 0.1);
  Eigen::VectorXd q0(100), qd0(100);
  for (int i = 0; i < 100; ++i) q0[i] = (i == 0 ? -1.2 : 0.0) + 0.05 * std::sin(0.3 * i), qd0[i] = 0.2 * std::cos(0.2 * i);
  double kinetic = 0;
  const double coarse = rk4EnergyDrift(chain, q0, qd0, 1e-3, 0.1, &kinetic);
  const double fine = rk4EnergyDrift(chain, q0, qd0, 5e-4, 0.1);
  INFO("drift at dt 1 ms " << coarse << " J, at 0.5 ms " << fine << " J, kinetic energy " << kinetic << " J");
  CHECK(coarse < 1e-6 * kinetic);
  CHECK(coarse / fine > 8);
}

TEST_CASE("VecIn views vectors in place and evaluates expressions (on the stack up to kMaxDof)") {
  const int m = kMaxDof + 16;  // longer than the stack buffer: evaluated on the heap
  Eigen::VectorXd big = Eigen::VectorXd::LinSpaced(m, 0, 1);
  const VecIn whole(big);
  CHECK(whole.data() == big.data());
  const VecIn head(big.head(10));
  CHECK(head.data() == big.data());
  VecN small = VecN::Ones(5);
  const VecIn expr(2 * small);
  CHECK(expr.data() != small.data());
  CHECK(expr.size() == 5);
  CHECK(expr[4] == 2.0);
  const VecIn large(2 * big);
  CHECK(large.size() == m);
  CHECK(large[m - 1] == 2.0);
  // pointJacobian's J (a MatN) cannot hold more than kMaxDof columns: it says so.
  const int n = kMaxDof + 6;
  const TreeModel<Planar> chain = uniformPlanarChain(n, 0.1, 1.0);
  TreeData<Planar> data(chain);
  positionKinematics(chain, Eigen::VectorXd::Zero(n), data);
  MatN J;
  CHECK_THROWS_AS(pointJacobian(chain, data, n - 1, Planar::Pos(0.1, 0.0), J), std::length_error);
}
