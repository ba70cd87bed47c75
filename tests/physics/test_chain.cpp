// Tree algorithms cross-checked against each other and against the Lagrangian:
// CRBA = RNEA columns, M SPD, ABA = M⁻¹(τ − h), Cθ'+G = d/dt ∂L/∂θ' − ∂L/∂θ by finite
// differences, J and J'θ' by finite differences, planar = spatial for a planar arm.
#include <doctest/doctest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

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

TEST_CASE("CRBA with massless carriers (the Σ Jᵀ I J form) equals RNEA columns") {
  // Three prismatic carriers (one placement turned), a heading joint, and two massive leaves on a
  // branch: 2 of 6 bodies carry mass, so crba takes its sparse-mass route.
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
