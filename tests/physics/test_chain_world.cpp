// The world-coordinate stages (chain_world.h) against the body-coordinate algorithms (chain.h):
// M from world composites = RNEA's columns, h = RNEA at θ'' = 0, the link velocities and velocity-product
// accelerations = the body-frame ones carried to the world origin, T = ½ θ'ᵀ M θ'. Trees with
// prismatic joints, turned placements, massless carriers and a branch.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <limits>

#include "physics/chain_world.h"
#include "tests/physics/arms.h"

using namespace dyn;

namespace {

TreeModel<Spatial> branchedSpatialTree() {
  using Pos = Spatial::Pos;
  TreeModel<Spatial> t;
  t.gravity << 0, 0, 0, 0, 0, -9.81;
  const Spatial::Transform turned{Eigen::AngleAxisd(0.4, Pos(1, 2, 3).normalized()).toRotationMatrix(), Pos(0.1, -0.2, 0.3)};
  const Eigen::Matrix3d Ic = (Eigen::Matrix3d() << 0.02, 0.003, -0.001, 0.003, 0.01, 0.002, -0.001, 0.002, 0.015).finished();
  int b = t.addBody(-1, JointType::Prismatic, Pos::UnitX(), Spatial::Transform(), Spatial::Mat::Zero());
  b = t.addBody(b, JointType::Prismatic, Pos(0, 1, 1), turned, Spatial::Mat::Zero());
  const int hub = t.addBody(b, JointType::Revolute, Pos::UnitZ(), Spatial::translation({0, 0, 0.2}), Spatial::inertia(1.2, Pos(0.02, 0, 0.05), Ic));
  t.addBody(hub, JointType::Revolute, Pos::UnitY(), turned, Spatial::inertia(2.0, Pos(0.05, 0.01, -0.02), Ic));
  t.addBody(hub, JointType::Revolute, Pos(1, 0, 1), Spatial::translation({0.3, 0, 0}), Spatial::inertia(0.7, Pos(0.2, 0, 0.1), 0.5 * Ic));
  return t;
}

TreeModel<Planar> planarWithSlider() {
  TreeModel<Planar> t = test::planarArm();
  t.addBody(2, JointType::Prismatic, Planar::Axis(1, 0), Planar::translation({0.2, 0.0}), Planar::inertia(0.4, Planar::Pos(0.01, 0.02), 0.001));
  return t;
}

template <class S>
void checkWorldStages(TreeModel<S> t, const VecN& q, const VecN& qd) {
  TreeData<S> body(t), world(t);
  const int n = t.dof();
  // M by columns of RNEA (body coordinates, independent of the composites): M e_j = ID(θ, 0, e_j) − G.
  forwardKinematics(t, q, VecN::Zero(n), body);
  const VecN G = rnea(t, body, VecN::Zero(n), VecN::Zero(n));
  MatN M(n, n);
  for (int j = 0; j < n; ++j) M.col(j) = rnea(t, body, VecN::Zero(n), VecN::Unit(n, j)) - G;
  forwardKinematics(t, q, qd, body);
  const VecN h = rnea(t, body, qd, VecN::Zero(n));  // leaves body.a: the velocity-product accelerations

  positionKinematics(t, q, world);
  // Every entry of M must be written (the branch's entries off the root paths as exact zeros): start from NaN.
  Eigen::MatrixXd Mw = Eigen::MatrixXd::Constant(n, n, std::numeric_limits<double>::quiet_NaN());
  crbaWorld(t, world, Mw);
  CHECK(Mw.allFinite());
  auto onPath = [&](int i, int j) {  // i on the path from j to the root
    for (int k = j; k >= 0; k = t.bodies[std::size_t(k)].parent)
      if (k == i) return true;
    return false;
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i)
      if (!onPath(i, j) && !onPath(j, i)) CHECK(Mw(i, j) == 0.0);
  Eigen::VectorXd hw(n);
  biasForcesWorld(t, world, qd, hw);

  const double scale = M.norm();
  CHECK((Mw - M).norm() < 1e-13 * scale);
  CHECK((Mw - Mw.transpose()).norm() == 0.0);
  CHECK((hw - h).norm() < 1e-12 * (1 + h.norm()));
  for (int i = 0; i < n; ++i) {
    const typename S::Vec v = S::motionInverse(body.X_world[i], body.v[i]);
    const typename S::Vec a = S::motionInverse(body.X_world[i], body.a[i]);
    CHECK((world.v_w[i] - v).norm() < 1e-13 * (1 + v.norm()));
    CHECK((world.a_w[i] - a).norm() < 1e-12 * (1 + a.norm()));
  }
  const double T = 0.5 * qd.dot(M * qd);
  CHECK(kineticEnergyWorld(t, world) == doctest::Approx(T).epsilon(1e-13));
  CHECK(kineticEnergy(t, body) == doctest::Approx(T).epsilon(1e-13));
}

}  // namespace

TEST_CASE("world-coordinate stages equal RNEA: spatial arm") {
  VecN q(3), qd(3);
  q << 0.3, -0.7, 1.1;
  qd << 0.9, -1.3, 0.7;
  checkWorldStages(test::spatialArm(), q, qd);
}

TEST_CASE("world-coordinate stages equal RNEA: carriers, turned placements, a branch") {
  VecN q(5), qd(5);
  q << 0.3, -0.7, 1.1, 0.5, -1.2;
  qd << 0.4, -0.2, 1.5, -0.8, 2.1;
  checkWorldStages(branchedSpatialTree(), q, qd);
}

TEST_CASE("world-coordinate stages equal RNEA: planar arm with a slider") {
  VecN q(4), qd(4);
  q << 0.3, -0.7, 1.1, 0.05;
  qd << 0.9, -1.3, 0.7, -0.3;
  checkWorldStages(planarWithSlider(), q, qd);
}

TEST_CASE("fast paths equal the general ones: joints about coordinate axes, diagonal central inertias") {
  // The same trees with every fast path switched off: the general Rodrigues transform, the full
  // product with X_world of the parent, the full I_c E.
  // An elbow arm of cylinders along their axes (the pen's kind: central inertias exactly diagonal).
  TreeModel<Spatial> cylinders;
  cylinders.gravity << 0, 0, 0, 0, 0, -9.81;
  const Eigen::Matrix3d Iz = Eigen::Vector3d(0.03, 0.03, 0.002).asDiagonal(), Ix = Eigen::Vector3d(0.001, 0.02, 0.02).asDiagonal();
  cylinders.addBody(-1, JointType::Revolute, Spatial::Pos::UnitZ(), Spatial::Transform(), Spatial::inertia(2.0, {0, 0, 0.15}, Iz));
  cylinders.addBody(0, JointType::Revolute, Spatial::Pos::UnitY(), Spatial::translation({0, 0, 0.3}), Spatial::inertia(1.5, {0.15, 0, 0}, Ix));
  cylinders.addBody(1, JointType::Revolute, Spatial::Pos::UnitX(), Spatial::translation({0.3, 0, 0}), Spatial::inertia(1.0, {0.17, 0, 0}, Ix));
  int axes = 0, diagonal = 0;
  for (const TreeModel<Spatial>& fast : {test::spatialArm(), branchedSpatialTree(), cylinders}) {
    TreeModel<Spatial> general = fast;
    for (auto& b : general.bodies) {
      axes += b.coordinate_axis >= 0;
      diagonal += b.central.diagonal && b.central.m > 0;
      b.coordinate_axis = -1;
      b.central.diagonal = false;
    }
    const int n = fast.dof();
    VecN q(n);
    for (int i = 0; i < n; ++i) q[i] = 0.7 * i - 1.1;
    TreeData<Spatial> a(fast), b(general);
    positionKinematics(fast, q, a);
    positionKinematics(general, q, b);
    for (int i = 0; i < n; ++i) {
      CHECK((a.X_world[i].E - b.X_world[i].E).norm() < 1e-15);
      CHECK((a.X_world[i].r - b.X_world[i].r).norm() < 1e-15);
      CHECK((a.X_up[i].E - b.X_up[i].E).norm() < 1e-15);
      CHECK((a.S_w[i] - b.S_w[i]).norm() < 1e-15);
    }
    // The mechanism's position stage computes the world part alone: the same numbers, bit for bit.
    TreeData<Spatial> w(fast);
    worldKinematics(fast, q, w);
    for (int i = 0; i < n; ++i) {
      CHECK(w.X_world[i].E == a.X_world[i].E);
      CHECK(w.X_world[i].r == a.X_world[i].r);
      CHECK(w.S_w[i] == a.S_w[i]);
    }
    Eigen::MatrixXd Ma(n, n), Mb(n, n);
    crbaWorld(fast, a, Ma);
    crbaWorld(general, b, Mb);
    CHECK((Ma - Mb).norm() < 1e-15 * Mb.norm());
  }
  // The fast paths were exercised: axes x, y, z (y also on a turned placement), diagonal inertias.
  CHECK(axes >= 8);
  CHECK(diagonal >= 3);
}

TEST_CASE("a coordinate-axis turn written in place has the bits of compose() and the turned rows") {
  // Spatial::turnAbout writes X_J ∘ X_tree ∘ P entry by entry (no whole-Transform copies): it must
  // sum in compose()'s order, for turned and unturned placements and parents alike.
  using Pos = Spatial::Pos;
  const Spatial::Transform turned{Eigen::AngleAxisd(0.4, Pos(1, 2, 3).normalized()).toRotationMatrix(), Pos(0.1, -0.2, 0.3)};
  const Spatial::Transform parent{Eigen::AngleAxisd(-1.3, Pos(-2, 1, 0.5).normalized()).toRotationMatrix(), Pos(0.7, 0.3, -0.9)};
  const Spatial::Transform shifted = Spatial::translation({0.3, -0.1, 0.2}), still = Spatial::marked(Spatial::Transform());
  int cases = 0;
  for (const Spatial::Transform& tree : {turned, shifted})
    for (const Spatial::Transform* P : {&parent, &still, static_cast<const Spatial::Transform*>(nullptr)})
      for (int k = 0; k < 3; ++k) {
        const double c = std::cos(0.3 + k), s = std::sin(0.3 + k);
        const Spatial::Transform X = P ? Spatial::compose(tree, *P) : tree;
        // E_J mixes rows i = k+1 and j = k+2 of X.E (E_J itself when X does not turn).
        const int i = (k + 1) % 3, j = (k + 2) % 3;
        Eigen::Matrix3d E = X.turned ? X.E : Eigen::Matrix3d::Identity();
        for (int col = 0; col < 3; ++col) {
          const double ei = E(i, col), ej = E(j, col);
          E(i, col) = c * ei + s * ej;
          E(j, col) = c * ej - s * ei;
        }
        Spatial::Transform out;
        Spatial::turnAbout(k, c, s, tree, P, out);
        CHECK(out.E == E);
        CHECK(out.r == X.r);
        CHECK(out.turned);
        ++cases;
      }
  CHECK(cases == 18);
}
