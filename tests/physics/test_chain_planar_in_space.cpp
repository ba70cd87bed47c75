// The planar kernels of a spatial tree moving in a plane (physics/chain_planar_in_space.h) against the
// 6-D ones (chain_sized.h kinematics, crbaWorld, biasForcesWorld; chain_world.h kineticEnergyWorld) on random
// planar trees: hinges about one world coordinate axis, slides in the plane, placements that turn
// about that axis (or not at all) and sit anywhere along it, central inertias with every product of
// inertia (in-plane and out-of-plane), massless carriers, branches, gravity in and out of the plane:
// the transforms and joint axes, M, h, the velocities and velocity-product accelerations left for the
// constraints, and the kinetic energy, to ~1e-13 relative. A tree that leaves its plane by 1e-3 anywhere is not taken as planar.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <random>

#include "physics/chain_planar_in_space.h"

using namespace dyn;

namespace {

using Pos = Spatial::Pos;

// A rotation about e_k by angle a, built exactly (row and column k exactly e_k): E rotates parent
// coordinates into the body's.
Spatial::Rot turnAbout(int k, double a) {
  const int i = k == 2 ? 0 : k + 1, j = i == 2 ? 0 : i + 1;
  Spatial::Rot E = Spatial::Rot::Identity();
  E(i, i) = E(j, j) = std::cos(a);
  E(i, j) = std::sin(a);
  E(j, i) = -std::sin(a);
  return E;
}

Spatial::Mat randomInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.1, 1.0);
  // A principal frame turned about a general axis: I_c has every product of inertia.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0 * u(rng), Pos(u(rng), -u(rng), u(rng)).normalized()).toRotationMatrix();
  const Eigen::Matrix3d Ic = R * Eigen::Vector3d(0.02 * u(rng), 0.03 * u(rng), 0.01 * u(rng)).asDiagonal() * R.transpose();
  return Spatial::inertia(2.0 * u(rng), Pos(0.1 * u(rng), -0.1 * u(rng), 0.2 * u(rng)), Ic);
}

// A random tree of n bodies moving in the plane ⊥ e_k, parents anywhere before; the first is a hinge.
TreeModel<Spatial> randomPlanarTree(std::mt19937& rng, int n, int k) {
  TreeModel<Spatial> t;
  t.gravity << 0, 0, 0, 1.5, -2.0, -9.81;  // out of the plane too
  std::uniform_int_distribution<int> kind(0, 4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  while (t.dof() < n) {
    const int parent = std::uniform_int_distribution<int>(-1, t.dof() - 1)(rng);
    const int c = t.dof() == 0 ? 0 : kind(rng);
    const Pos r = 0.3 * Pos(u(rng), u(rng), u(rng));
    const Spatial::Transform X = c % 2 == 0 ? Spatial::Transform{turnAbout(k, 3.0 * u(rng)), r, true} : Spatial::translation(r);
    const Spatial::Mat I = c == 4 ? Spatial::Mat::Zero() : randomInertia(rng);  // some massless
    if (c == 3) {
      Pos axis(u(rng), u(rng), u(rng));
      axis[k] = 0.0;  // in the plane
      t.addBody(parent, JointType::Prismatic, axis, X, I);
    } else {
      t.addBody(parent, JointType::Revolute, Pos::Unit(k), X, I);
    }
  }
  return t;
}

double relative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) { return (a - b).norm() / (1.0 + b.norm()); }

// One random planar tree of N bodies (Dynamic: n) at a random state, planar kernels against the 6-D.
template <int N>
void checkPlanar(std::mt19937& rng, int n, int k, int* slides, int* massless) {
  const TreeModel<Spatial> t = randomPlanarTree(rng, n, k);
  REQUIRE(planeNormalAxis(t) == k);
  for (const auto& b : t.bodies) *slides += b.joint == JointType::Prismatic, *massless += b.massless;
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  VecN q(n), qd(n);
  for (int i = 0; i < n; ++i) q[i] = u(rng), qd[i] = u(rng);
  TreeData<Spatial> world(t), planar(t);
  PlanarTreeData P(t);
  sized::kinematics<false, N>(t, q, world);
  sized::kinematicsPlanar<N>(t, q, planar, P);
  for (int i = 0; i < n; ++i) {
    CHECK((planar.X_world[i].E - world.X_world[i].E).norm() < 1e-14);
    CHECK((planar.X_world[i].r - world.X_world[i].r).norm() < 1e-14);
    CHECK((planar.S_w[i] - world.S_w[i]).norm() < 1e-14);
  }
  Eigen::MatrixXd Mw(n, n), Mp(n, n);
  Eigen::VectorXd hw(n), hp(n);
  sized::crbaWorld<N>(t, world, Mw);
  sized::crbaPlanar<N>(t, planar, P, Mp);
  CHECK(relative(Mp, Mw) < 1e-13);
  CHECK(Mp == Mp.transpose());
  sized::biasForcesWorld<N>(t, world, qd, hw);
  sized::biasForcesPlanar<N>(t, planar, P, qd, hp);
  CHECK(relative(hp, hw) < 1e-13);
  // What the constraints read: V and A of every body, in 6-D, zero out of the plane.
  for (int i = 0; i < n; ++i) {
    CHECK((planar.v_w[i] - world.v_w[i]).norm() < 1e-13 * (1.0 + world.v_w[i].norm()));
    CHECK((planar.a_w[i] - world.a_w[i]).norm() < 1e-13 * (1.0 + world.a_w[i].norm()));
  }
  const double T = kineticEnergyWorld(t, world);
  CHECK(kineticEnergyPlanar(P) == doctest::Approx(T).epsilon(1e-13));
  CHECK(kineticEnergyWorldOrPlanar(t, planar, P) == kineticEnergyPlanar(P));
}

}  // namespace

TEST_CASE("the planar kernels give the 6-D kernels' X_world, S_w, M, h, V, A and kinetic energy on random planar trees") {
  std::mt19937 rng(43);
  int slides = 0, massless = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int k = trial % 3;
    checkPlanar<4>(rng, 4, k, &slides, &massless);
    checkPlanar<7>(rng, 7, k, &slides, &massless);
    checkPlanar<Eigen::Dynamic>(rng, 5 + trial % 6, k, &slides, &massless);
  }
  CHECK(slides > 20);  // every kind of body was drawn
  CHECK(massless > 20);
}

TEST_CASE("a tree that leaves its plane by 1e-3 anywhere, or has a ball joint, does not take the planar path") {
  std::mt19937 rng(5);
  for (int trial = 0; trial < 30; ++trial) {
    const int k = trial % 3, n = 3 + trial % 4;
    const TreeModel<Spatial> planar = randomPlanarTree(rng, n, k);
    REQUIRE(planeNormalAxis(planar) == k);
    const int b = std::uniform_int_distribution<int>(0, n - 1)(rng);
    const Pos tilt = Pos::Unit(k == 0 ? 1 : 0);
    // One hinge's axis tilted (kept unit: addBody normalises it), rebuilt from the same bodies.
    auto rebuilt = [&](auto change) {
      TreeModel<Spatial> t;
      t.gravity = planar.gravity;
      for (int i = 0; i < n; ++i) {
        auto body = planar.bodies[std::size_t(i)];
        if (i == b) change(body);
        t.addBody(body.parent, body.joint, body.axis, body.X_tree, body.inertia);
      }
      return t;
    };
    CHECK(planeNormalAxis(rebuilt([&](auto& body) {
            body.joint = JointType::Revolute;
            body.axis = Pos(Pos::Unit(k) + 1e-3 * tilt);
          })) == -1);
    // A placement turned about another axis by 1e-3.
    CHECK(planeNormalAxis(rebuilt([&](auto& body) { body.X_tree.E = body.X_tree.E * Eigen::AngleAxisd(1e-3, tilt).toRotationMatrix().transpose(); })) == -1);
    // A slide with a component along e_k.
    CHECK(planeNormalAxis(rebuilt([&](auto& body) {
            body.joint = JointType::Prismatic;
            body.axis = Pos(tilt + 1e-3 * Pos::Unit(k));
          })) == -1);
    // A hinge about −e_k (Rodrigues' E(k, k) = c + (1 − c) need not be 1 exactly): not taken either.
    CHECK(planeNormalAxis(rebuilt([&](auto& body) {
            body.joint = JointType::Revolute;
            body.axis = -Pos::Unit(k);
          })) == -1);
    // Gravity with an angular part.
    TreeModel<Spatial> turning_gravity = planar;
    turning_gravity.gravity[k] = 1e-3;
    CHECK(planeNormalAxis(turning_gravity) == -1);
    // A ball joint anywhere.
    TreeModel<Spatial> with_ball = planar;
    with_ball.addBall(0, Spatial::translation(Pos(0.1, 0.2, 0.3)), Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity(), randomInertia(rng));
    CHECK(planeNormalAxis(with_ball) == -1);
  }
  // Slides alone: no hinge to name the plane.
  TreeModel<Spatial> slides;
  slides.addBody(-1, JointType::Prismatic, Pos(1, 0, 0), Spatial::translation(Pos::Zero()), randomInertia(rng));
  CHECK(planeNormalAxis(slides) == -1);
}
