// The tree recursions a mechanism's stage runs (chain.h positionKinematics / worldKinematics,
// chain_world.h crbaWorld and biasForcesWorld), written once for a body count N known at compile
// time (a fixed instantiation of ConstrainedMechanism: the model files' PUMA and five-bar, the labs)
// or Eigen::Dynamic (chain.cpp and chain_world.cpp instantiate that). Each is the same sequence of
// floating-point operations at either size, so M, h and the transforms are bit for bit the same;
// a fixed N only lets the body loops unroll and the bodies' data stay in registers.
#pragma once
#include "physics/chain.h"
#include "physics/det/det.h"
#include "physics/det/sincos.h"
#include "physics/spatial_lanes.h"

namespace dyn::sized {

template <int N, class S>
DYN_INLINE int bodyCount(const TreeModel<S>& model) {
  if constexpr (N == Eigen::Dynamic) return model.dof();
  else return N;
}

// A ball's sub-body i: the first turns by pre R(Q/|Q|) R0ᵀ after its placement, the other two sit on
// it (identity placement).
template <bool kParentFrames, class S>
void ballKinematics(const TreeModel<S>& model, int i, const VecIn& q, TreeData<S>& data) {
  const auto& b = model.bodies[std::size_t(i)];
  typename S::Transform X_up;
  if constexpr (S::kDim == 6) {
    const auto& ball = model.balls[std::size_t(b.ball)];
    if (i == ball.first) {
      const int k = b.q_index;
      const Eigen::Quaterniond Q(q[k], q[k + 1], q[k + 2], q[k + 3]);
      // E rotates parent coordinates into the body's: the transpose of the relative rotation.
      const typename S::Rot E = ball.post * Q.normalized().toRotationMatrix().transpose() * ball.pre.transpose();
      X_up = S::compose(typename S::Transform{E, S::Pos::Zero(), true}, b.X_tree);
    } else {
      X_up = S::translation(S::Pos::Zero());
    }
  }
  if constexpr (kParentFrames) data.X_up[i] = X_up;
  data.X_world[i] = b.parent < 0 ? X_up : S::compose(X_up, data.X_world[b.parent]);
  data.S_w[i] = S::motionInverse(data.X_world[i], b.subspace);
}

// positionKinematics, and with kParentFrames false its world part alone (X_world, S_w).
template <bool kParentFrames, int N, class S>
void kinematics(const TreeModel<S>& model, const VecIn& q, TreeData<S>& data) {
  const int n = bodyCount<N>(model);
  for (int i = 0; i < n; ++i) {
    const auto& b = model.bodies[i];
    if constexpr (kParentFrames) data.S_i[i] = b.subspace;
    if constexpr (S::kDim == 6) {
      // A revolute joint about a coordinate axis: X_world = X_J ∘ (X_tree ∘ X_world,parent) turns two
      // rows, and its world axis is a row of E (spatial.h turnAbout, coordinateAxisInWorld). About −e_k
      // by θ is about e_k by −θ: sin negated, cos kept, the world axis negated (all exact).
      if (b.joint == JointType::Revolute && b.coordinate_axis >= 0) {
        double c, s;
        det::sincos(q[b.q_index], s, c);  // det::cos and det::sin, one reduction
        if (b.coordinate_sign < 0) s = -s;
        const int k = b.coordinate_axis;
        if constexpr (kParentFrames) S::turnAbout(k, c, s, b.X_tree, nullptr, data.X_up[i]);
        S::turnAbout(k, c, s, b.X_tree, b.parent < 0 ? nullptr : &data.X_world[b.parent], data.X_world[i]);
        S::coordinateAxisInWorld(k, b.coordinate_sign < 0, data.X_world[i], data.S_w[i]);
        continue;
      }
    }
    if (b.joint == JointType::Ball) {
      ballKinematics<kParentFrames>(model, i, q, data);
      continue;
    }
    // Joint placement then joint motion: X_up = X_J(θ_i) X_tree.
    const typename S::Transform X_up = S::compose(S::jointTransform(b.joint == JointType::Revolute, b.axis, q[b.q_index]), b.X_tree);
    if constexpr (kParentFrames) data.X_up[i] = X_up;
    data.X_world[i] = b.parent < 0 ? X_up : S::compose(X_up, data.X_world[b.parent]);
    data.S_w[i] = S::motionInverse(data.X_world[i], b.subspace);
  }
}

// A serial chain: each body's parent the one before it (the PUMA, the pen, the unicycle's carriers).
template <class Model>
DYN_INLINE bool isSerialChain(const Model& model, int n) {
  bool chain = true;
  for (int i = 0; i < n; ++i) chain = chain && model.bodies[std::size_t(i)].parent == i - 1;
  return chain;
}

// CRBA's last pass (crbaWorld, and chain_planar_in_space.h's crbaPlanar on 3-vectors): with F_j the
// force that moving joint j alone needs (force(j) = I_c,j S_j), M_ij = S_i · F_j for every joint i on
// the path from j to the root (parents precede their children), zero for the joints off it. Each
// entry written once (M is symmetric): no zeroing pass first, which for a small M is a memset call.
// A serial chain (`serial`: isSerialChain, which the caller has evaluated already) has every i ≤ j on
// the path: its own loop, without the walk, unrolls whole at a fixed n.
template <class Alg, class Model, class Force, class MatOut>
DYN_INLINE void fillJointSpaceInertia(const Model& model, int n, bool serial, const std::vector<typename Alg::Vec>& axes, const Force& force,
                                      MatOut& M) {
  if (serial) {
    for (int j = 0; j < n; ++j) {
      const typename Alg::Vec F = force(j);
      for (int i = j; i >= 0; --i) M(i, j) = M(j, i) = Alg::dot(axes[std::size_t(i)], F);
    }
    return;
  }
  for (int j = 0; j < n; ++j) {
    const typename Alg::Vec F = force(j);
    for (int r = j, i = j; r >= 0; --r)
      if (r == i) {
        M(i, j) = M(j, i) = Alg::dot(axes[std::size_t(i)], F);
        i = model.bodies[std::size_t(i)].parent;
      } else {
        M(r, j) = M(j, r) = 0.0;
      }
  }
}

// RNEA's net force on one body, f_i = I_i (A_i − g) + V_i ×* I_i V_i (netForces' one lane, T = double),
// from data.I_w, v_w and a_w; zero on a massless body.
template <class S>
DYN_INLINE void netForceOne(const TreeModel<S>& model, const TreeData<S>& data, int i, typename S::Vec& f) {
  if (model.bodies[std::size_t(i)].massless) {
    f.setZero();
    return;
  }
  double I[S::kInertiaNumbers];
  S::inertiaNumbers(data.I_w[i], I);
  S::netForce(I, data.v_w[i].data(), data.a_w[i].data(), model.gravity.data(), f.data());
}

// netForces on a pair whose world inertias are still in lanes (worldInertias: m, h and I_O's lower
// triangle; I_O is symmetric, its (i, j) above the diagonal the (j, i) stored): the numbers netForces
// reads back from data.I_w, without the stores' round trip.
template <class S>
DYN_INLINE void netForcePair(const TreeModel<S>& model, const TreeData<S>& data, int a, int b, const Lanes2& m, const Lanes2* h,
                             const Lanes2 (&Io)[3][3], typename S::Vec* f) {
  Lanes2 I[S::kInertiaNumbers], v[6], acc[6], g[6], out[6];
  I[0] = m;
  for (int i = 0; i < 3; ++i) I[1 + i] = h[i];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) I[4 + 3 * i + j] = j <= i ? Io[i][j] : Io[j][i];
  for (int k = 0; k < 6; ++k) {
    v[k] = Lanes2{data.v_w[a][k], data.v_w[b][k]}, acc[k] = Lanes2{data.a_w[a][k], data.a_w[b][k]};
    g[k] = Lanes2{model.gravity[k], model.gravity[k]};
  }
  S::netForce(I, v, acc, g, out);
  for (int k = 0; k < 6; ++k) f[a][k] = out[k][0], f[b][k] = out[k][1];
}

// CRBA's world inertias I_i^w (kept for the velocity stage) of a 6-D tree, each also its composite's
// first term; on a serial chain (`serial`) leaves to root, each composite I_i^w + I_c,i+1 as it is
// written (the sums the composite pass makes, without storing the body's own and reading it back).
// Bodies go two at a time, (i − 1, i) from the leaf end, one a lane (spatial_lanes.h: each lane the
// one-body code's bits): a body's transform of its central inertia needs no other body's, and one
// body's alone leaves most of the CPU's multipliers idle. A pair with a massless body (the unicycle's
// carriers, nothing to compute) or whose bodies take different branches goes one body at a time.
// With f (crbaAndBiasSerial: data.v_w and a_w staged), each body's RNEA net force too, from its world
// inertia as it is made (netForcePair, netForceOne: netForces' bits).
template <class S>
DYN_INLINE void worldInertias(const TreeModel<S>& model, TreeData<S>& data, int n, bool serial, typename S::Vec* f = nullptr) {
  for (int b = n - 1; b >= 0; b -= 2) {
    const int a = b - 1;  // −1: an odd count's root, alone
    const auto& B = model.bodies[std::size_t(b)];
    const typename S::Inertia* childB = serial && b + 1 < n ? &data.Ic_rb[b + 1] : nullptr;
    const typename S::Inertia* childA = serial ? &data.Ic_rb[b] : nullptr;
    if (a >= 0) {
      const auto& A = model.bodies[std::size_t(a)];
      Lanes2 h[3], Io[3][3];
      if (!A.massless && !B.massless && lanes::worldInertiaPair(data.X_world[a], A.central, data.X_world[b], B.central, h, Io)) {
        lanes::storeLane(1, B.central.m, h, Io, data.I_w[b], data.Ic_rb[b], childB);
        lanes::storeLane(0, A.central.m, h, Io, data.I_w[a], data.Ic_rb[a], childA);
        if (f) netForcePair(model, data, a, b, Lanes2{A.central.m, B.central.m}, h, Io, f);
        continue;
      }
    }
    lanes::worldInertia(data.X_world[b], B.central, B.massless, data.I_w[b], data.Ic_rb[b], childB);
    if (f) netForceOne(model, data, b, f[b]);
    if (a >= 0) {
      const auto& A = model.bodies[std::size_t(a)];
      lanes::worldInertia(data.X_world[a], A.central, A.massless, data.I_w[a], data.Ic_rb[a], childA);
      if (f) netForceOne(model, data, a, f[a]);
    }
  }
}

// fillJointSpaceInertia on a 6-D serial chain, two columns (j, j + 1) at a time, one a lane: their
// forces F_j = I_c,j S_j (independent), then each S_i · F on both (spatial_lanes.h: the bits of
// Spatial::inertiaTimes and dot in each lane); an odd count's last column alone.
template <class S, class MatOut>
DYN_INLINE void fillSerialInPairs(const TreeData<S>& data, int n, MatOut& M) {
  for (int j = 0; j < n; j += 2) {
    const int l = j + 1 < n ? j + 1 : j;
    Lanes2 F[6];
    lanes::forcePair(data.Ic_rb[j], data.S_w[j], data.Ic_rb[l], data.S_w[l], F);
    for (int i = 0; i <= j; ++i) {
      const Lanes2 d = lanes::dotPair(data.S_w[i], F);
      M(i, j) = M(j, i) = d[0];
      if (l != j) M(i, l) = M(l, i) = d[1];
    }
    if (l != j) M(l, l) = lanes::dotPair(data.S_w[l], F)[1];
  }
}

// M's columns on a 6-D serial chain whose composites worldInertias has summed: in pairs from four
// bodies on (with three, the pen's, the lanes' packing cost more than the pairs saved in a harness,
// 0.327 -> 0.337 µs a step), else the scalar fill.
template <class S, class MatOut>
DYN_INLINE void fillSerialColumns(const TreeModel<S>& model, const TreeData<S>& data, int n, MatOut& M) {
  if (n >= 4) return fillSerialInPairs(data, n, M);
  fillJointSpaceInertia<S>(model, n, true, data.S_w, [&](int j) { return S::inertiaTimes(data.Ic_rb[j], data.S_w[j]); }, M);
}

// chain_world.h crbaWorld: M(θ) from world composite inertias, leaving data.I_w.
template <int N, class S, class MatOut>
void crbaWorld(const TreeModel<S>& model, TreeData<S>& data, MatOut& M) {
  const int n = bodyCount<N>(model);
  const bool serial = isSerialChain(model, n);
  if constexpr (S::kDim == 6) {
    worldInertias(model, data, n, serial);  // a serial chain's composites summed with them
    if (serial) return fillSerialColumns(model, data, n, M);
  } else {
    for (int i = 0; i < n; ++i) {
      const auto& b = model.bodies[std::size_t(i)];
      if (b.massless) data.I_w[i].setZero(), data.Ic_rb[i].setZero();
      else S::inertiaInParent(data.X_world[i], b.inertia, data.I_w[i], data.Ic_rb[i]);  // planar: from the origin form
    }
  }
  // Composite inertias, leaves to root: in one frame they simply add.
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.bodies[std::size_t(i)].parent;
    if (p >= 0) data.Ic_rb[p] += data.Ic_rb[i];
  }
  fillJointSpaceInertia<S>(model, n, serial, data.S_w, [&](int j) { return S::inertiaTimes(data.Ic_rb[j], data.S_w[j]); }, M);
}

// RNEA's net force on each massive body, f_i = I_i (A_i − g) + V_i ×* I_i V_i, from data.I_w, v_w and
// a_w, into f[i] (zero on a massless body). Bodies go two at a time, one a lane (S::netForce: each lane
// the bits of the scalar inertiaTimes and crossForce): the bodies' forces are independent, and the
// 6-vectors of one body alone keep too many values live for 16 registers (spills).
template <class S>
DYN_INLINE void netForces(const TreeModel<S>& model, const TreeData<S>& data, int n, typename S::Vec* f) {
  constexpr int D = S::kDim, K = S::kInertiaNumbers;
  Lanes2 g[D];
  for (int k = 0; k < D; ++k) g[k] = Lanes2{model.gravity[k], model.gravity[k]};
#pragma GCC unroll 4
  for (int i = 0; i < n; i += 2) {
    const int j = i + 1 < n ? i + 1 : i;  // an odd count: the last body in both lanes
    // Two massless carriers (the unicycle's): nothing to compute, as the loop before lanes skipped them.
    if (model.bodies[std::size_t(i)].massless && model.bodies[std::size_t(j)].massless) {
      f[i].setZero(), f[j].setZero();
      continue;
    }
    double A[K], B[K];
    S::inertiaNumbers(data.I_w[i], A);
    S::inertiaNumbers(data.I_w[j], B);
    Lanes2 I[K], v[D], a[D], out[D];
    for (int k = 0; k < K; ++k) I[k] = Lanes2{A[k], B[k]};
    for (int k = 0; k < D; ++k) v[k] = Lanes2{data.v_w[i][k], data.v_w[j][k]}, a[k] = Lanes2{data.a_w[i][k], data.a_w[j][k]};
    S::netForce(I, v, a, g, out);
    for (int k = 0; k < D; ++k) f[i][k] = out[k][0], f[j][k] = out[k][1];
    if (model.bodies[std::size_t(i)].massless) f[i].setZero();
    if (model.bodies[std::size_t(j)].massless) f[j].setZero();
  }
}

// biasForcesSerial's way out: V_i = V_i−1 + S_i θ'_i and A_i = A_i−1 + V_i ×m S_i θ'_i, the parent's V
// and A carried in registers (not read back from v_w, a_w), the root's V_parent = 0 and A = 0 without a
// sum; into data.v_w and data.a_w.
template <int N, class S>
DYN_INLINE void velocitiesSerial(TreeData<S>& data, int n, const VecN& qd) {
  using Vec = typename S::Vec;
  Vec v, a;  // the body's V_i and A_i, its parent's while the next is begun
#pragma GCC unroll 8
  for (int i = 0; i < n; ++i) {
    // Entry by entry, not Eigen's assignments: at a dynamic size the unrolled loops make this function
    // large enough that GCC stops inlining those (a call per sum, through memory).
    Vec vJ;
    for (int k = 0; k < S::kDim; ++k) vJ[k] = data.S_w[i][k] * qd[i];
    if (i == 0) {
      for (int k = 0; k < S::kDim; ++k) v[k] = vJ[k], a[k] = 0.0;
    } else {
      for (int k = 0; k < S::kDim; ++k) v[k] = v[k] + vJ[k];
      const Vec c = S::crossMotion(v, vJ);
      for (int k = 0; k < S::kDim; ++k) a[k] = a[k] + c[k];
    }
    for (int k = 0; k < S::kDim; ++k) data.v_w[i][k] = v[k], data.a_w[i][k] = a[k];
  }
}

// biasForcesSerial's way in: each subtree's force summed in registers as h's dot products read it
// (F_i = f_i + F_i+1, the sums the tree's f_p += f_i makes), h_i = S_i · F_i.
template <class S, class VecOut>
DYN_INLINE void forcesInSerial(const TreeData<S>& data, int n, const typename S::Vec* f, VecOut& h) {
  typename S::Vec F;
  for (int k = 0; k < S::kDim; ++k) F[k] = f[n - 1][k];
  h[n - 1] = S::dot(data.S_w[n - 1], F);
#pragma GCC unroll 8
  for (int i = n - 2; i >= 0; --i) {
    for (int k = 0; k < S::kDim; ++k) F[k] = f[i][k] + F[k];
    h[i] = S::dot(data.S_w[i], F);
  }
}

// biasForcesWorld on a serial chain without ball joints (the PUMA, the impedance arm): velocitiesSerial,
// netForces, forcesInSerial. The same floating-point operations, in the same order, as the tree loop
// below: the same bits. data.f is not left at a fixed size (nothing reads it after this; rnea in
// chain.cpp writes its own).
template <int N, class S, class VecOut>
DYN_INLINE void biasForcesSerial(const TreeModel<S>& model, TreeData<S>& data, const VecN& qd, VecOut& h) {
  const int n = bodyCount<N>(model);
  typename S::Vec local[N == Eigen::Dynamic ? 1 : N];
  typename S::Vec* f = N == Eigen::Dynamic ? data.f.data() : local;  // each body's own net force
  velocitiesSerial<N>(data, n, qd);
  netForces(model, data, n, f);
  forcesInSerial(data, n, f, h);
}

// crbaWorld and biasForcesWorld at once on a 6-D serial chain without ball joints (both stages at one
// state: constrained_mechanism_impl.h stageBoth): the velocities out, then each pair of bodies' world
// inertias, composites and net forces while their numbers are in lanes (worldInertias with f), M's
// columns, the forces in. Each quantity the same floating-point operations in the same order as the two
// apart (a body's net force in a lane of its own, whichever pair it is in): the same M, h, I_w, Ic_rb,
// v_w and a_w bits; saved: netForces reading back the world inertias stored a stage before.
template <int N, class S, class MatOut, class VecOut>
void crbaAndBiasSerial(const TreeModel<S>& model, TreeData<S>& data, const VecN& qd, MatOut& M, VecOut& h) {
  static_assert(S::kDim == 6, "6-D chains: worldInertias' lanes");
  const int n = bodyCount<N>(model);
  typename S::Vec local[N == Eigen::Dynamic ? 1 : N];
  typename S::Vec* f = N == Eigen::Dynamic ? data.f.data() : local;
  velocitiesSerial<N>(data, n, qd);
  worldInertias(model, data, n, true, f);
  fillSerialColumns(model, data, n, M);
  forcesInSerial(data, n, f, h);
}

// Whether crbaAndBiasSerial fits a tree: a 6-D serial chain of at least one body without ball joints.
template <int N, class S>
bool fusedSerial(const TreeModel<S>& model) {
  const int n = bodyCount<N>(model);
  return S::kDim == 6 && n > 0 && model.balls.empty() && isSerialChain(model, n);
}

// chain_world.h biasForcesWorld: h = C θ' + G, leaving data.v_w and data.a_w.
template <int N, class S, class VecOut>
void biasForcesWorld(const TreeModel<S>& model, TreeData<S>& data, const VecN& qd, VecOut& h) {
  using Vec = typename S::Vec;
  const int n = bodyCount<N>(model);
  if (n > 0 && model.balls.empty() && isSerialChain(model, n)) return biasForcesSerial<N>(model, data, qd, h);
  // Outward: velocities and velocity-product accelerations; then each massive body's net force.
  for (int i = 0; i < n; ++i) {
    const auto& b = model.bodies[std::size_t(i)];
    const Vec vJ = data.S_w[i] * qd[i];
    data.v_w[i] = b.parent < 0 ? vJ : Vec(data.v_w[b.parent] + vJ);
    // (A root's V_i ×m S_i θ'_i is S_i θ'_i × itself: zero. A ball's sub-body: V_parent ×m S_i θ'_i,
    // without its siblings' rates: chain.h.)
    int anchor = i;
    if (b.joint == JointType::Ball) anchor = model.bodies[std::size_t(model.balls[std::size_t(b.ball)].first)].parent;
    const Vec c = b.parent < 0 || anchor < 0 ? Vec(Vec::Zero()) : S::crossMotion(data.v_w[anchor], vJ);
    data.a_w[i] = b.parent < 0 ? c : Vec(data.a_w[b.parent] + c);
  }
  netForces(model, data, n, data.f.data());
  // Inward: each joint carries its subtree's forces (same frame: a sum).
  for (int i = n - 1; i >= 0; --i) {
    h[i] = S::dot(data.S_w[i], data.f[i]);
    const int p = model.bodies[std::size_t(i)].parent;
    if (p >= 0) data.f[p] += data.f[i];
  }
}

}  // namespace dyn::sized
