// The tree kernels at a body count fixed at compile time (physics/chain_sized.h, what a fixed
// instantiation of the mechanism runs) against the dynamically sized ones (chain.h, chain_world.h):
// the same transforms, M and h bit for bit on random trees and serial chains with revolute joints
// about coordinate and general axes, prismatic and ball joints, turned and plain placements, massless
// carriers and branches; M against RNEA's columns and h against RNEA(θ, θ', 0) as an independent reference; and
// Spatial::compose's products written out against Eigen's; det::sincos against det::sin and det::cos;
// h (bodies' net forces two at a time, serial chains in registers) against the one-body-at-a-time
// world-frame RNEA written here, bit for bit; and M and the world inertias (two bodies and two columns
// at a time, spatial_lanes.h) against the one-body-at-a-time CRBA written here, bit for bit (an unturned
// pair's too, after the stack is dirtied: no lane read unloaded); and CRBA
// with the bias forces in one pass (crbaAndBiasSerial) against the two apart, bit for bit.
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
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


// crbaWorld as it was written before its bodies and columns went two at a time (spatial_lanes.h): one
// body at a time, each world inertia from the centre-of-mass form (Spatial::inertiaInParent as it was),
// composites summed in a pass, each column's force from Spatial::inertiaTimes, M_ij = S_i · F_j on j's
// path, zero off it. Leaves I_w and Ic in world and composite.
Spatial::Inertia worldInertiaOneBody(const Spatial::Transform& X, const Spatial::Central& C) {
  Spatial::Inertia out;
  out.m = C.m;
  Pos cA;
  double B[3][3], Io[3][3];
  if (X.turned) {
    for (int i = 0; i < 3; ++i) cA[i] = X.r[i] + X.E(0, i) * C.c[0] + X.E(1, i) * C.c[1] + X.E(2, i) * C.c[2];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        B[i][j] = C.diagonal ? C.Ic(i, i) * X.E(i, j) : C.Ic(i, 0) * X.E(0, j) + C.Ic(i, 1) * X.E(1, j) + C.Ic(i, 2) * X.E(2, j);
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) Io[i][j] = X.E(0, i) * B[0][j] + X.E(1, i) * B[1][j] + X.E(2, i) * B[2][j];
  } else {
    for (int i = 0; i < 3; ++i) cA[i] = X.r[i] + C.c[i];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) Io[i][j] = C.Ic(i, j);
  }
  for (int i = 0; i < 3; ++i) out.h[i] = C.m * cA[i];
  const double mcc = out.h[0] * cA[0] + out.h[1] * cA[1] + out.h[2] * cA[2];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) out.Io(i, j) = out.Io(j, i) = Io[i][j] - out.h[i] * cA[j] + (i == j ? mcc : 0.0);
  return out;
}

Eigen::MatrixXd crbaOneByOne(const TreeModel<Spatial>& model, const TreeData<Spatial>& data, std::vector<Spatial::Inertia>& world,
                             std::vector<Spatial::Inertia>& composite) {
  const int n = model.dof();
  world.assign(std::size_t(n), Spatial::Inertia{});
  for (int i = 0; i < n; ++i)
    if (!model.bodies[std::size_t(i)].massless) world[std::size_t(i)] = worldInertiaOneBody(data.X_world[i], model.bodies[std::size_t(i)].central);
  composite = world;
  for (int i = n - 1; i >= 0; --i)
    if (model.bodies[std::size_t(i)].parent >= 0) composite[std::size_t(model.bodies[std::size_t(i)].parent)] += composite[std::size_t(i)];
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    const Spatial::Vec F = Spatial::inertiaTimes(composite[std::size_t(j)], data.S_w[j]);
    for (int i = j; i >= 0; i = model.bodies[std::size_t(i)].parent) M(i, j) = M(j, i) = Spatial::dot(data.S_w[i], F);
  }
  return M;
}

bool sameBits(const Spatial::Inertia& a, const Spatial::Inertia& b) {
  return std::memcmp(&a.m, &b.m, sizeof(double)) == 0 && std::memcmp(a.h.data(), b.h.data(), sizeof(double) * 3) == 0 &&
         std::memcmp(a.Io.data(), b.Io.data(), sizeof(double) * 9) == 0;
}

// A random tree or chain (randomTree) whose bodies a die (0-5) makes massless below `massless`, or,
// massive, gives a diagonal central inertia (the lanes' other branch) below `diagonal`: pairs of
// massless bodies, and of one of each, are then common.
TreeModel<Spatial> randomTreeMixed(std::mt19937& rng, int n, bool chain, int massless, int diagonal) {
  TreeModel<Spatial> t = randomTree(rng, n, chain);
  std::uniform_int_distribution<int> coin(0, 5);
  for (auto& b : t.bodies) {
    const int k = coin(rng);
    if (k < massless) b.massless = true, b.central = Spatial::Central{};
    else if (k < diagonal && !b.massless) b.central.Ic = Eigen::Matrix3d(b.central.Ic.diagonal().asDiagonal()), b.central.diagonal = true;
  }
  return t;
}

template <int N>
void checkCrbaOneByOne(std::mt19937& rng, bool chain, int* pairs) {
  const TreeModel<Spatial> t = randomTreeMixed(rng, N, chain, 2, 4);
  REQUIRE(t.dof() == N);
  for (int i = 0; i + 1 < N; ++i) *pairs += !t.bodies[std::size_t(i)].massless && !t.bodies[std::size_t(i + 1)].massless;
  const VecN q = randomConfiguration(rng, t);
  TreeData<Spatial> d(t);
  sized::kinematics<false, N>(t, q, d);
  Eigen::Matrix<double, N, N> M;
  sized::crbaWorld<N>(t, d, M);
  std::vector<Spatial::Inertia> world, composite;
  const Eigen::MatrixXd M1 = crbaOneByOne(t, d, world, composite);
  REQUIRE(std::memcmp(M.data(), M1.data(), sizeof(double) * N * N) == 0);  // the signs of zeros too
  for (int i = 0; i < N; ++i) {
    REQUIRE(sameBits(d.I_w[i], world[std::size_t(i)]));
    REQUIRE(sameBits(d.Ic_rb[i], composite[std::size_t(i)]));
  }
  Eigen::MatrixXd Md(N, N);
  TreeData<Spatial> dd(t);
  worldKinematics(t, q, dd);
  crbaWorld(t, dd, Md);  // the dynamic size
  REQUIRE(std::memcmp(Md.data(), M1.data(), sizeof(double) * N * N) == 0);
}

// crbaAndBiasSerial (CRBA and the bias forces in one pass) against crbaWorld then biasForcesWorld on
// a random serial chain (massless bodies and diagonal central inertias as checkCrbaOneByOne draws them),
// bit for bit: M, h and every body's I_w, Ic_rb, v_w and a_w. A chain with a ball joint or a tree is
// not the fused kernel's (fusedSerial false).
template <int N>
void checkFused(std::mt19937& rng, bool chain, int* fused) {
  const TreeModel<Spatial> t = randomTreeMixed(rng, N, chain, 1, 3);
  REQUIRE(t.dof() == N);
  const bool fits = t.balls.empty() && sized::isSerialChain(t, N);
  REQUIRE(sized::fusedSerial<N>(t) == fits);
  if (!fits) return;
  ++*fused;
  const VecN q = randomConfiguration(rng, t);
  VecN qd(N);
  for (int i = 0; i < N; ++i) qd[i] = std::uniform_real_distribution<double>(-3.0, 3.0)(rng);
  TreeData<Spatial> apart(t), once(t);
  sized::kinematics<false, N>(t, q, apart);
  sized::kinematics<false, N>(t, q, once);
  Eigen::Matrix<double, N, N> M, Mf;
  Eigen::Matrix<double, N, 1> h, hf;
  sized::crbaWorld<N>(t, apart, M);
  sized::biasForcesWorld<N>(t, apart, qd, h);
  sized::crbaAndBiasSerial<N>(t, once, qd, Mf, hf);
  REQUIRE(std::memcmp(M.data(), Mf.data(), sizeof(double) * N * N) == 0);  // the signs of zeros too
  REQUIRE(std::memcmp(h.data(), hf.data(), sizeof(double) * N) == 0);
  for (int i = 0; i < N; ++i) {
    REQUIRE(sameBits(apart.I_w[i], once.I_w[i]));
    REQUIRE(sameBits(apart.Ic_rb[i], once.Ic_rb[i]));
    REQUIRE(std::memcmp(apart.v_w[i].data(), once.v_w[i].data(), sizeof(double) * 6) == 0);
    REQUIRE(std::memcmp(apart.a_w[i].data(), once.a_w[i].data(), sizeof(double) * 6) == 0);
  }
}
}  // namespace

TEST_CASE("CRBA and the bias forces in one pass give crbaWorld's and biasForcesWorld's bits") {
  std::mt19937 rng(8243);
  int fused = 0;
  for (int trial = 0; trial < 60; ++trial) {
    checkFused<1>(rng, true, &fused);
    checkFused<2>(rng, true, &fused);
    checkFused<3>(rng, trial % 4 != 0, &fused);  // the scalar columns (fewer than four bodies)
    checkFused<4>(rng, true, &fused);
    checkFused<5>(rng, trial % 4 != 0, &fused);  // odd: the root alone in worldInertias
    checkFused<6>(rng, trial % 4 != 0, &fused);
    checkFused<7>(rng, true, &fused);
  }
  CHECK(fused > 250);  // most chains drew no ball joint
}

// Stack memory below the caller filled with a non-zero pattern: a kernel called next that reads a lane
// it never wrote reads this, not a lucky zero.
[[gnu::noinline]] double dirtyStack() {
  volatile double junk[2048];
  for (int i = 0; i < 2048; ++i) junk[i] = 0.5 + i;
  return junk[2047];
}

TEST_CASE("an untransformed pair's world inertias (both in the world's axes, diagonal I_c) are one body's bits") {
  // Two prismatic joints on translated placements: both bodies' X_world unturned, so the pair's lanes
  // take centralInWorld's untransformed branch, which reads I_c's off-diagonal (zero) entries too.
  TreeModel<Spatial> t;
  t.gravity << 0, 0, 0, 0, 0, -9.81;
  const Eigen::Matrix3d Ic = Eigen::Vector3d(0.02, 0.03, 0.01).asDiagonal();
  t.addBody(-1, JointType::Prismatic, Pos(0.3, 0.5, 0.1).normalized(), Spatial::translation(Pos(0.1, 0.2, 0.3)),
            Spatial::inertia(1.5, Pos(0.1, -0.1, 0.2), Ic));
  t.addBody(0, JointType::Prismatic, Pos::UnitZ(), Spatial::translation(Pos(0.0, 0.4, 0.0)), Spatial::inertia(0.7, Pos(-0.2, 0.1, 0.05), Ic));
  REQUIRE(t.bodies[0].central.diagonal);
  REQUIRE(t.bodies[1].central.diagonal);
  VecN q(2);
  q << 0.3, -0.4;
  TreeData<Spatial> d(t);
  sized::kinematics<false, 2>(t, q, d);
  REQUIRE(!d.X_world[0].turned);
  REQUIRE(!d.X_world[1].turned);
  Eigen::Matrix<double, 2, 2> M;
  REQUIRE(dirtyStack() > 0.0);
  sized::crbaWorld<2>(t, d, M);
  for (int i = 0; i < 2; ++i) CHECK(sameBits(d.I_w[i], worldInertiaOneBody(d.X_world[i], t.bodies[std::size_t(i)].central)));
}

TEST_CASE("M with bodies' world inertias and M's columns two at a time is one-body-at-a-time CRBA's, bit for bit") {
  std::mt19937 rng(4302);
  int pairs = 0;
  for (int trial = 0; trial < 80; ++trial) {
    checkCrbaOneByOne<1>(rng, true, &pairs);
    checkCrbaOneByOne<2>(rng, trial % 2 == 0, &pairs);
    checkCrbaOneByOne<5>(rng, trial % 2 == 0, &pairs);  // odd: the root alone, the last column alone
    checkCrbaOneByOne<6>(rng, trial % 2 == 0, &pairs);
    checkCrbaOneByOne<7>(rng, trial % 3 == 0, &pairs);
  }
  CHECK(pairs > 200);  // massive neighbours: the lanes were taken
}

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
