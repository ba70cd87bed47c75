// The tree kernels at a body count fixed at compile time (physics/chain_sized.h, what a fixed
// instantiation of the mechanism runs) against the dynamically sized ones (chain.h, chain_world.h):
// the same transforms, M and h bit for bit on random trees and serial chains with revolute joints
// about coordinate and general axes, prismatic and ball joints, turned and plain placements, massless
// carriers and branches; M against RNEA's columns and h against RNEA(θ, θ', 0) as an independent reference; and
// Spatial::compose's products written out against Eigen's; det::sincos against det::sin and det::cos;
// h (bodies' net forces two at a time, serial chains in registers) against the one-body-at-a-time
// world-frame RNEA written here, bit for bit.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "physics/chain_sized.h"
#include "physics/chain_world.h"
#include "physics/det/det.h"
#include "physics/det/sincos.h"

using namespace dyn;

namespace {

using Pos = Spatial::Pos;

Spatial::Transform randomTransform(std::mt19937& rng, bool turned) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Pos r(u(rng), u(rng), u(rng));
  if (!turned) return Spatial::translation(0.3 * r);
  return {Eigen::AngleAxisd(3.0 * u(rng), Pos(u(rng), u(rng), u(rng)).normalized()).toRotationMatrix(), 0.3 * r, true};
}

Spatial::Mat randomInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.1, 1.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(3.0 * u(rng), Pos(u(rng), -u(rng), u(rng)).normalized()).toRotationMatrix();
  const Eigen::Matrix3d Ic = R * Eigen::Vector3d(0.02 * u(rng), 0.03 * u(rng), 0.01 * u(rng)).asDiagonal() * R.transpose();
  return Spatial::inertia(2.0 * u(rng), Pos(0.1 * u(rng), -0.1 * u(rng), 0.2 * u(rng)), Ic);
}

// A random tree of exactly n bodies (a ball joint takes three), parents anywhere before; or a serial
// chain (each body's parent the one before it: crbaWorld's unwalked loop).
TreeModel<Spatial> randomTree(std::mt19937& rng, int n, bool chain = false) {
  TreeModel<Spatial> t;
  t.gravity << 0, 0, 0, 0.5, -1.0, -9.81;
  std::uniform_int_distribution<int> kind(0, 5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  while (t.dof() < n) {
    const int parent = chain ? t.dof() - 1 : std::uniform_int_distribution<int>(-1, t.dof() - 1)(rng);
    const int k = kind(rng);
    const Spatial::Transform X = randomTransform(rng, k % 2 == 0);
    const Spatial::Mat I = k == 5 ? Spatial::Mat::Zero() : randomInertia(rng);  // some massless
    if (k == 4 && t.dof() + 3 <= n) {
      const Eigen::Matrix3d post = Eigen::AngleAxisd(u(rng), Pos(1, u(rng), 0).normalized()).toRotationMatrix();
      t.addBall(parent, Spatial::marked(Spatial::translation(X.r)), Eigen::Matrix3d::Identity(), post, randomInertia(rng));
    } else if (k == 3) {
      t.addBody(parent, JointType::Prismatic, Pos(u(rng), u(rng), u(rng)), X, I);
    } else {
      const Pos axis = k <= 1 ? Pos(Pos::Unit(std::uniform_int_distribution<int>(0, 2)(rng))) : Pos(u(rng), u(rng), u(rng));
      t.addBody(parent, JointType::Revolute, axis, X, I);
    }
  }
  return t;
}

VecN randomConfiguration(std::mt19937& rng, const TreeModel<Spatial>& t) {
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  VecN q(t.nq());
  for (int i = 0; i < t.nq(); ++i) q[i] = u(rng);
  normalizeConfiguration(t, q);
  return q;
}

template <int N>
void checkSized(std::mt19937& rng, int* balls, int* prismatic, bool chain = false) {
  const TreeModel<Spatial> t = randomTree(rng, N, chain);
  REQUIRE(t.dof() == N);
  *balls += int(t.balls.size());
  for (const auto& b : t.bodies) *prismatic += b.joint == JointType::Prismatic;
  const VecN q = randomConfiguration(rng, t);
  VecN qd(N);
  for (int i = 0; i < N; ++i) qd[i] = std::uniform_real_distribution<double>(-3.0, 3.0)(rng);
  TreeData<Spatial> dynamic(t), sized(t);
  worldKinematics(t, q, dynamic);
  sized::kinematics<false, N>(t, q, sized);
  for (int i = 0; i < N; ++i) {
    REQUIRE(sized.X_world[i].E == dynamic.X_world[i].E);
    REQUIRE(sized.X_world[i].r == dynamic.X_world[i].r);
    REQUIRE(sized.S_w[i] == dynamic.S_w[i]);
  }
  Eigen::MatrixXd M(N, N);
  Eigen::Matrix<double, N, N> Ms;
  crbaWorld(t, dynamic, M);
  sized::crbaWorld<N>(t, sized, Ms);
  REQUIRE(Eigen::MatrixXd(Ms) == M);
  Eigen::VectorXd h(N);
  Eigen::Matrix<double, N, 1> hs;
  biasForcesWorld(t, dynamic, qd, h);
  sized::biasForcesWorld<N>(t, sized, qd, hs);
  REQUIRE(Eigen::VectorXd(hs) == h);
  // Against RNEA in body coordinates (written apart): M e_j = ID(θ, 0, e_j) − G, h = ID(θ, θ', 0).
  TreeData<Spatial> body(t);
  forwardKinematics(t, q, VecN::Zero(N), body);
  const VecN G = rnea(t, body, VecN::Zero(N), VecN::Zero(N));
  for (int j = 0; j < N; ++j) {
    const VecN col = rnea(t, body, VecN::Zero(N), VecN::Unit(N, j)) - G;
    CHECK((Ms.col(j) - col).norm() <= 1e-12 * (1.0 + M.norm()));
  }
  forwardKinematics(t, q, qd, body);
  CHECK((hs - rnea(t, body, qd, VecN::Zero(N))).norm() <= 1e-12 * (1.0 + h.norm()));
}

// biasForcesWorld as it was written before its bodies went two at a time (Spatial::netForce's lanes)
// and serial chains got their own loop: one body at a time, each net force from the Inertia's
// inertiaTimes and crossForce, summed inward in data.f.
template <int N>
Eigen::Matrix<double, N, 1> biasForcesOneByOne(const TreeModel<Spatial>& model, TreeData<Spatial>& data, const VecN& qd) {
  using Vec = Spatial::Vec;
  Eigen::Matrix<double, N, 1> h;
  std::vector<Vec> v(N), a(N), f(N);
  for (int i = 0; i < N; ++i) {
    const auto& b = model.bodies[std::size_t(i)];
    const Vec vJ = data.S_w[i] * qd[i];
    v[i] = b.parent < 0 ? vJ : Vec(v[b.parent] + vJ);
    int anchor = i;
    if (b.joint == JointType::Ball) anchor = model.bodies[std::size_t(model.balls[std::size_t(b.ball)].first)].parent;
    const Vec c = b.parent < 0 || anchor < 0 ? Vec(Vec::Zero()) : Spatial::crossMotion(v[anchor], vJ);
    a[i] = b.parent < 0 ? c : Vec(a[b.parent] + c);
    if (b.massless) {
      f[i].setZero();
      continue;
    }
    const Vec acc = a[i] - model.gravity;
    f[i] = Spatial::inertiaTimes(data.I_w[i], acc) + Spatial::crossForce(v[i], Spatial::inertiaTimes(data.I_w[i], v[i]));
  }
  for (int i = N - 1; i >= 0; --i) {
    h[i] = Spatial::dot(data.S_w[i], f[i]);
    const int p = model.bodies[std::size_t(i)].parent;
    if (p >= 0) f[p] += f[i];
  }
  for (int i = 0; i < N; ++i) {
    REQUIRE(data.v_w[i] == v[i]);
    REQUIRE(data.a_w[i] == a[i]);
  }
  return h;
}

template <int N>
void checkBiasOneByOne(std::mt19937& rng, bool chain, int* serial) {
  const TreeModel<Spatial> t = randomTree(rng, N, chain);
  REQUIRE(t.dof() == N);
  *serial += t.balls.empty() && sized::isSerialChain(t, N);
  const VecN q = randomConfiguration(rng, t);
  VecN qd(N);
  for (int i = 0; i < N; ++i) qd[i] = std::uniform_real_distribution<double>(-3.0, 3.0)(rng);
  TreeData<Spatial> d(t);
  Eigen::Matrix<double, N, N> M;
  sized::kinematics<false, N>(t, q, d);
  sized::crbaWorld<N>(t, d, M);
  Eigen::Matrix<double, N, 1> h;
  sized::biasForcesWorld<N>(t, d, qd, h);
  REQUIRE(h == biasForcesOneByOne<N>(t, d, qd));
  Eigen::VectorXd hd(N);
  biasForcesWorld(t, d, qd, hd);  // the dynamic size: data.f's loop
  REQUIRE(Eigen::VectorXd(h) == hd);
}

}  // namespace

TEST_CASE("h with bodies two at a time (and a serial chain in registers) is one-body-at-a-time RNEA's, bit for bit") {
  std::mt19937 rng(2611);
  int serial = 0;
  for (int trial = 0; trial < 60; ++trial) {
    checkBiasOneByOne<1>(rng, true, &serial);
    checkBiasOneByOne<5>(rng, trial % 2 == 0, &serial);  // odd: the last body in both lanes
    checkBiasOneByOne<6>(rng, trial % 2 == 0, &serial);
    checkBiasOneByOne<7>(rng, trial % 3 == 0, &serial);
  }
  CHECK(serial > 40);  // serial chains' own loop was taken
}

TEST_CASE("the tree kernels at a fixed body count give the dynamic ones' transforms, M and h bit for bit") {
  std::mt19937 rng(43);
  int balls = 0, prismatic = 0;
  for (int trial = 0; trial < 40; ++trial) {
    checkSized<4>(rng, &balls, &prismatic);
    checkSized<6>(rng, &balls, &prismatic);
    checkSized<9>(rng, &balls, &prismatic);
    checkSized<6>(rng, &balls, &prismatic, true);  // serial chains, as the PUMA
    checkSized<9>(rng, &balls, &prismatic, true);
  }
  CHECK(balls > 10);  // every kind of joint was drawn
  CHECK(prismatic > 10);
}

TEST_CASE("a serial chain's M (crbaWorld's unwalked paths) equals the walked tree's bit for bit") {
  // The same chain with a massless leaf on its root is a tree (the walk, the composite pass): its M
  // has the chain's M in the top-left block (the leaf adds zeros, its column of M is zero).
  std::mt19937 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 2 + trial % 8;
    const TreeModel<Spatial> chain = randomTree(rng, n, true);
    if (chain.dof() != n) continue;
    TreeModel<Spatial> tree = chain;
    tree.addBody(0, JointType::Revolute, Pos::UnitX(), Spatial::translation(Pos(0.1, 0.2, 0.3)), Spatial::Mat::Zero());
    const VecN q = randomConfiguration(rng, chain);
    VecN qt(tree.nq());
    qt << q, 0.4;
    TreeData<Spatial> dc(chain), dt(tree);
    worldKinematics(chain, q, dc);
    worldKinematics(tree, qt, dt);
    Eigen::MatrixXd Mc(n, n), Mt(n + 1, n + 1);
    crbaWorld(chain, dc, Mc);
    crbaWorld(tree, dt, Mt);
    REQUIRE(Mc == Mt.topLeftCorner(n, n));
    CHECK(Mt.col(n).isZero(0.0));
  }
}

TEST_CASE("compose() written out sums as Eigen's 3x3 products: the same bits") {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const Spatial::Transform bc = randomTransform(rng, trial % 3 != 0), ab = randomTransform(rng, trial % 4 != 0);
    const Spatial::Transform X = Spatial::compose(bc, ab);
    const Eigen::Matrix3d E = bc.turned && ab.turned ? Eigen::Matrix3d(bc.E * ab.E) : ab.turned ? ab.E : bc.E;
    const Pos r = ab.turned ? Pos(ab.r + ab.E.transpose() * bc.r) : Pos(ab.r + bc.r);
    REQUIRE(X.E == E);
    REQUIRE(X.r == r);
    CHECK(X.turned == (bc.turned || ab.turned));
  }
}

TEST_CASE("det::sincos gives det::sin and det::cos bit for bit") {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> xs = {0.0, -0.0, 1e-30, -1e-9, 0.7853981633974483, -0.7853981633974484, 1.5707963267948966, 3.141592653589793,
                            -4.71238898038469, 1e5, -2e6, 1e300, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()};
  for (int i = 0; i < 4000; ++i) xs.push_back(u(rng) * (i % 4 == 0 ? 1.0 : i % 4 == 1 ? 10.0 : i % 4 == 2 ? 1e3 : 1e7));
  for (double x : xs) {
    double s, c;
    det::sincos(x, s, c);
    const double s0 = det::sin(x), c0 = det::cos(x);
    INFO(x);
    if (std::isnan(s0)) {
      CHECK(std::isnan(s));
      CHECK(std::isnan(c));
      continue;
    }
    CHECK(std::signbit(s) == std::signbit(s0));
    CHECK(std::signbit(c) == std::signbit(c0));
    CHECK(s == s0);
    CHECK(c == c0);
  }
}
