// Hinges about −e_k on the coordinate-axis path (chain.h markCoordinateAxis, chain_sized.h kinematics,
// spatial.h coordinateAxisInWorld): a turn by θ about −e_k is a turn by −θ about +e_k, so with D the
// diagonal of the hinges' signs (−1 for −e_k, +1 otherwise) the same tree built about +e_k gives, at
// D θ and D θ', the same transforms bit for bit, S^w = D S'^w, M = D M' D and h = D h' exactly (sin is
// odd and cos even bit for bit, and a negation is exact). Against the general Rodrigues path (every
// fast path off), to rounding. Random trees: branches, turned placements, slides, massless carriers,
// full and diagonal inertias; the fixed-size instantiation equals the dynamic one bit for bit. A
// planar tree with one hinge about −e_k is left to the 6-D path (planeNormalAxis).
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <random>

#include "physics/chain_planar_in_space.h"
#include "physics/chain_sized.h"
#include "physics/chain_world.h"

using namespace dyn;

namespace {

using Pos = Spatial::Pos;

// A random tree of n bodies: hinges about ±e_k (most), about a general axis, and slides; parents
// anywhere before (or each the one before: a serial chain).
TreeModel<Spatial> randomTree(std::mt19937& rng, int n, bool serial) {
  TreeModel<Spatial> t;
  t.gravity << 0, 0, 0, 0.5, -1.0, -9.81;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 9), axis(0, 2);
  while (t.dof() < n) {
    const int parent = serial ? t.dof() - 1 : std::uniform_int_distribution<int>(-1, t.dof() - 1)(rng);
    const int c = kind(rng);
    const Pos r = 0.3 * Pos(u(rng), u(rng), u(rng));
    const Spatial::Transform X = c % 3 == 0 ? Spatial::Transform{Eigen::AngleAxisd(2.0 * u(rng), Pos(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix(), r, true}
                                            : Spatial::translation(r);
    const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0 * u(rng), Pos(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix();
    const Eigen::Vector3d moments(0.02 + 0.01 * u(rng), 0.03 + 0.01 * u(rng), 0.015 + 0.01 * u(rng));
    const Eigen::Matrix3d Ic = c % 2 == 0 ? Eigen::Matrix3d(moments.asDiagonal()) : Eigen::Matrix3d(R * moments.asDiagonal() * R.transpose());
    const Spatial::Mat I = c == 9 ? Spatial::Mat::Zero() : Spatial::inertia(1.5 + u(rng), 0.1 * Pos(u(rng), u(rng), u(rng)), Ic);
    if (c == 8) t.addBody(parent, JointType::Prismatic, Pos(u(rng), u(rng), u(rng)), X, I);
    else if (c == 7) t.addBody(parent, JointType::Revolute, Pos(u(rng), u(rng), u(rng)), X, I);
    else t.addBody(parent, JointType::Revolute, (u(rng) < 0 ? -1.0 : 1.0) * Pos::Unit(axis(rng)), X, I);
  }
  return t;
}

// The same tree with every hinge about −e_k turned about +e_k; sign: D's diagonal.
TreeModel<Spatial> mirrored(const TreeModel<Spatial>& t, VecN& sign) {
  TreeModel<Spatial> m = t;
  sign = VecN::Ones(t.dof());
  for (int i = 0; i < t.dof(); ++i) {
    auto& b = m.bodies[std::size_t(i)];
    if (b.joint != JointType::Revolute || b.coordinate_sign > 0) continue;
    sign[i] = -1.0;
    b.axis = -b.axis;
    b.subspace = m.motionSubspace(i);
    TreeModel<Spatial>::markCoordinateAxis(b);
    REQUIRE(b.coordinate_sign == 1);
  }
  return m;
}

struct Stages {
  TreeData<Spatial> data;
  Eigen::MatrixXd M;
  Eigen::VectorXd h;
  Stages(const TreeModel<Spatial>& t, const VecN& q, const VecN& qd) : data(t), M(t.dof(), t.dof()), h(t.dof()) {
    positionKinematics(t, q, data);
    crbaWorld(t, data, M);
    biasForcesWorld(t, data, qd, h);
  }
};

}  // namespace

TEST_CASE("a hinge about -e_k by q is the hinge about +e_k by -q: transforms, S^w, M and h exactly") {
  std::mt19937 rng(43);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int negative = 0, trees = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const TreeModel<Spatial> t = randomTree(rng, 2 + trial % 7, trial % 2 == 0);
    VecN D;
    const TreeModel<Spatial> m = mirrored(t, D);
    negative += int((D.array() < 0).count());
    const int n = t.dof();
    VecN q(n), qd(n);
    for (int i = 0; i < n; ++i) q[i] = 4.0 * u(rng), qd[i] = 3.0 * u(rng);
    const VecN Dq = D.asDiagonal() * q, Dqd = D.asDiagonal() * qd;
    Stages a(t, q, qd), b(m, Dq, Dqd);
    for (int i = 0; i < n; ++i) {
      CHECK(a.data.X_world[i].E == b.data.X_world[i].E);
      CHECK(a.data.X_world[i].r == b.data.X_world[i].r);
      CHECK(a.data.X_up[i].E == b.data.X_up[i].E);
      CHECK(a.data.S_w[i] == D[i] * b.data.S_w[i]);
    }
    CHECK(a.M == Eigen::MatrixXd(D.asDiagonal() * b.M * D.asDiagonal()));
    CHECK(a.h == Eigen::VectorXd(D.asDiagonal() * b.h));
    ++trees;
  }
  CHECK(trees == 60);
  CHECK(negative >= 60);  // the −e_k path was exercised, many times
}

TEST_CASE("hinges about -e_k: the coordinate-axis path equals the general Rodrigues path to rounding") {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int negative = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const TreeModel<Spatial> fast = randomTree(rng, 2 + trial % 7, trial % 2 == 1);
    TreeModel<Spatial> general = fast;
    for (auto& b : general.bodies) {
      negative += b.joint == JointType::Revolute && b.coordinate_axis >= 0 && b.coordinate_sign < 0;
      b.coordinate_axis = -1;
      b.central.diagonal = false;
    }
    const int n = fast.dof();
    VecN q(n), qd(n);
    for (int i = 0; i < n; ++i) q[i] = 4.0 * u(rng), qd[i] = 3.0 * u(rng);
    Stages a(fast, q, qd), b(general, q, qd);
    for (int i = 0; i < n; ++i) {
      CHECK((a.data.X_world[i].E - b.data.X_world[i].E).norm() < 1e-14);
      CHECK((a.data.X_world[i].r - b.data.X_world[i].r).norm() < 1e-14);
      CHECK((a.data.X_up[i].E - b.data.X_up[i].E).norm() < 1e-14);
      CHECK((a.data.S_w[i] - b.data.S_w[i]).norm() < 1e-14);
    }
    CHECK((a.M - b.M).norm() < 1e-13 * b.M.norm());
    CHECK((a.h - b.h).norm() < 1e-13 * (1.0 + b.h.norm()));
    // The fixed-size instantiation (a mechanism's) does the same operations: bit for bit.
    if (n == 6) {
      TreeData<Spatial> w(fast);
      Eigen::Matrix<double, 6, 6> M6;
      sized::kinematics<true, 6>(fast, q, w);
      sized::crbaWorld<6>(fast, w, M6);
      for (int i = 0; i < n; ++i) CHECK(w.X_world[i].E == a.data.X_world[i].E);
      CHECK(Eigen::MatrixXd(M6) == a.M);
    }
  }
  CHECK(negative >= 40);
}

TEST_CASE("planar in space: a tree with a hinge about -e_k is left to the 6-D path, its mirror about +e_k is planar") {
  for (int k = 0; k < 3; ++k) {
    TreeModel<Spatial> t;
    t.addBody(-1, JointType::Revolute, Pos::Unit(k), Spatial::translation({0.1, 0.2, 0.3}), Spatial::inertia(1.0, {0.1, 0.05, 0.02}, Eigen::Matrix3d::Identity() * 0.01));
    t.addBody(0, JointType::Revolute, Pos::Unit(k), Spatial::translation({0.3, -0.1, 0.2}), Spatial::inertia(0.5, {0.1, 0.0, 0.02}, Eigen::Matrix3d::Identity() * 0.02));
    CHECK(planeNormalAxis(t) == k);
    VecN D;
    t.bodies[1].axis = -Pos::Unit(k);
    t.bodies[1].subspace = t.motionSubspace(1);
    TreeModel<Spatial>::markCoordinateAxis(t.bodies[1]);
    CHECK(t.bodies[1].coordinate_axis == k);
    CHECK(t.bodies[1].coordinate_sign == -1);
    CHECK(planeNormalAxis(t) == -1);
    CHECK(planeNormalAxis(mirrored(t, D)) == k);
  }
}
