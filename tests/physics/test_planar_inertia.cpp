// Planar rigid-body inertias in their 4 numbers (physics/spatial.h Planar::Inertia: m, g = m ẑ×c, I_O)
// against the 3×3 form I = [[I_O, gᵀ], [g, m 1]] they stand for:
//   Xᵀ I X (inertiaInParent) against the product motionMatrix(X)ᵀ I motionMatrix(X), and bit for bit
//   against the closed form written as a 3×3 matrix (the form CRBA used before);
//   I v (inertiaTimes) against the 3×3 product;
//   CRBA's M and the bias h (physics/chain_sized.h, planar trees) against the same recursions run here
//   on 3×3 inertias, summed as matrices: the same bits, on random trees with revolute and prismatic
//   joints, turned and plain placements, massless carriers and branches.
#include <doctest/doctest.h>

#include <random>
#include <vector>

#include "physics/chain_sized.h"
#include "physics/chain_world.h"

using namespace dyn;

namespace {

using Mat = Planar::Mat;
using Pos = Planar::Pos;
using Vec = Planar::Vec;

Mat randomInertia(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return Planar::inertia(1.0 + 0.9 * u(rng), Pos(0.3 * u(rng), 0.2 * u(rng)), 0.02 + 0.01 * u(rng));
}

Planar::Transform randomTransform(std::mt19937& rng, bool turned) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  return {turned ? Planar::rotation(3.0 * u(rng)) : Planar::Rot(Planar::Rot::Identity()), Pos(0.5 * u(rng), 0.5 * u(rng))};
}

// The closed form of Xᵀ I X as a 3×3 matrix (the form the composite inertias had as Planar::Mat).
Mat inParentFull(const Planar::Transform& X, const Mat& I) {
  const double m = I(1, 1);
  const Pos g = Planar::rotateBack(X.E, I(1, 0), I(2, 0));
  const double px = -X.r.y(), py = X.r.x();
  const double gx = g.x() + m * px, gy = g.y() + m * py;
  Mat out;
  out << I(0, 0) + 2.0 * (g.x() * px + g.y() * py) + m * (px * px + py * py), gx, gy,  //
      gx, m, 0,                                                                    //
      gy, 0, m;
  return out;
}

// I v on the 3×3 form, reading the entries a rigid-body inertia has.
Vec timesFull(const Mat& I, const Vec& v) {
  const double m = I(1, 1), gx = I(1, 0), gy = I(2, 0);
  return {I(0, 0) * v[0] + gx * v[1] + gy * v[2], gx * v[0] + m * v[1], gy * v[0] + m * v[2]};
}

bool sameBits(const Planar::Inertia& c, const Mat& I) {
  return c.m == I(1, 1) && c.gx == I(1, 0) && c.gy == I(2, 0) && c.io == I(0, 0) && I(2, 2) == I(1, 1) && I(1, 0) == I(0, 1) &&
         I(2, 0) == I(0, 2) && I(1, 2) == 0 && I(2, 1) == 0;
}

TreeModel<Planar> randomTree(std::mt19937& rng, int n) {
  TreeModel<Planar> t;
  t.gravity << 0, 0.3, -9.81;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  while (t.dof() < n) {
    const int parent = std::uniform_int_distribution<int>(-1, t.dof() - 1)(rng);
    const int k = std::uniform_int_distribution<int>(0, 4)(rng);
    const Mat I = k == 4 ? Mat(Mat::Zero()) : randomInertia(rng);  // some massless carriers
    if (k == 3) t.addBody(parent, JointType::Prismatic, Pos(u(rng), u(rng)).normalized(), randomTransform(rng, true), I);
    else t.addBody(parent, JointType::Revolute, Pos::Zero(), randomTransform(rng, k % 2 == 0), I);
  }
  return t;
}

// CRBA and the bias forces of chain_sized.h, run on 3×3 inertias summed as matrices.
template <int N>
void referenceFull(const TreeModel<Planar>& t, const TreeData<Planar>& d, const VecN& qd, Eigen::Matrix<double, N, N>& M,
                   Eigen::Matrix<double, N, 1>& h) {
  std::vector<Mat> Iw(N), Ic(N);
  for (int i = 0; i < N; ++i) Iw[i] = Ic[i] = t.bodies[i].massless ? Mat(Mat::Zero()) : inParentFull(d.X_world[i], t.bodies[i].inertia);
  for (int i = N - 1; i >= 0; --i)
    if (t.bodies[i].parent >= 0) Ic[t.bodies[i].parent] += Ic[i];
  M.setZero();
  for (int j = 0; j < N; ++j) {
    const Vec F = timesFull(Ic[j], d.S_w[j]);
    for (int i = j; i >= 0; i = t.bodies[i].parent) M(i, j) = M(j, i) = Planar::dot(d.S_w[i], F);
  }
  std::vector<Vec> v(N), a(N), f(N);
  for (int i = 0; i < N; ++i) {
    const int p = t.bodies[i].parent;
    const Vec vJ = d.S_w[i] * qd[i];
    v[i] = p < 0 ? vJ : Vec(v[p] + vJ);
    const Vec c = p < 0 ? Vec(Vec::Zero()) : Planar::crossMotion(v[i], vJ);  // V_i ×m S_i θ'_i (chain_sized.h)
    a[i] = p < 0 ? c : Vec(a[p] + c);
    if (t.bodies[i].massless) {
      f[i].setZero();
      continue;
    }
    const Vec acc = a[i] - t.gravity;
    f[i] = timesFull(Iw[i], acc) + Planar::crossForce(v[i], timesFull(Iw[i], v[i]));
  }
  for (int i = N - 1; i >= 0; --i) {
    h[i] = Planar::dot(d.S_w[i], f[i]);
    if (t.bodies[i].parent >= 0) f[t.bodies[i].parent] += f[i];
  }
}

template <int N>
void checkTree(std::mt19937& rng) {
  const TreeModel<Planar> t = randomTree(rng, N);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  VecN q(N), qd(N);
  for (int i = 0; i < N; ++i) q[i] = u(rng), qd[i] = u(rng);
  TreeData<Planar> d(t);
  sized::kinematics<false, N>(t, q, d);
  Eigen::Matrix<double, N, N> M, Mref;
  Eigen::Matrix<double, N, 1> h, href;
  sized::crbaWorld<N>(t, d, M);
  sized::biasForcesWorld<N>(t, d, qd, h);
  referenceFull<N>(t, d, qd, Mref, href);
  REQUIRE(M == Mref);
  REQUIRE(h == href);
  // The dynamically sized kernels (chain_world.h) alike.
  TreeData<Planar> dyn_data(t);
  worldKinematics(t, q, dyn_data);
  Eigen::MatrixXd Md(N, N);
  Eigen::VectorXd hd(N);
  crbaWorld(t, dyn_data, Md);
  biasForcesWorld(t, dyn_data, qd, hd);
  REQUIRE(Md == Eigen::MatrixXd(Mref));
  REQUIRE(hd == Eigen::VectorXd(href));
}

}  // namespace

TEST_CASE("a planar inertia's 4 numbers: Xᵀ I X and I v as the 3×3 form's, bit for bit, and as the matrix product") {
  std::mt19937 rng(2026);
  std::uniform_real_distribution<double> u(-2.0, 2.0);
  for (int trial = 0; trial < 500; ++trial) {
    const Mat I = randomInertia(rng);
    const Planar::Transform X = randomTransform(rng, trial % 3 != 0);
    const Planar::Inertia c = Planar::inertiaInParent(X, I);
    const Mat full = inParentFull(X, I);
    REQUIRE(sameBits(c, full));
    const Mat Xm = Planar::motionMatrix(X);
    CHECK((Mat(Xm.transpose() * I * Xm) - full).norm() <= 1e-13 * (1.0 + full.norm()));
    REQUIRE(sameBits(Planar::compact(I), I));
    const Vec v(u(rng), u(rng), u(rng));
    const Vec Iv = Planar::inertiaTimes(c, v);
    REQUIRE(Iv == timesFull(full, v));
    REQUIRE(Planar::inertiaTimes(full, v) == Iv);
    CHECK((full * v - Iv).norm() <= 1e-13 * (1.0 + Iv.norm()));
    // Composites: 4 sums, the 3×3 sums' bits.
    Planar::Inertia sum = c;
    sum += Planar::inertiaInParent(X, full);
    REQUIRE(sameBits(sum, Mat(full + inParentFull(X, full))));
  }
}

TEST_CASE("planar CRBA and bias forces on compact inertias give the 3×3 form's M and h bit for bit") {
  std::mt19937 rng(43);
  for (int trial = 0; trial < 60; ++trial) {
    checkTree<3>(rng);
    checkTree<5>(rng);
    checkTree<8>(rng);
  }
}
