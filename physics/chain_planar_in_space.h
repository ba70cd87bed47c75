// A spatial tree that moves in a plane: chain_sized.h's crbaWorld and biasForcesWorld on its three
// non-zero components. When every joint is a hinge about the same world coordinate axis e_k (its axis
// e_k in its frame, every placement turning about e_k or not at all) or a slide perpendicular to it,
// every body turns about e_k alone and translates in the plane ⊥ e_k, in every configuration. With
// (x, y, z) = (e_i, e_j, e_k), i = k+1 and j = k+2 (mod 3), a right-handed frame:
//   S_i^w, V_i, A_i  have only (ω_z; v_x, v_y)                  the planar motion vector (spatial.h Planar)
//   I_i^w V          has in-plane part (J ω + g·v; g ω + m v)   J = I_c,zz + m (c_x² + c_y²), g = m (−c_y, c_x)
// with c the world centre of mass and I_c,zz the central inertia about the body's e_k (= e_k in the
// world: a rotation about e_k keeps it). The out-of-plane parts of I V (moments about e_i, e_j from
// I_c's products of inertia, a force along e_k) and of gravity along e_k load only the joints'
// bearings, never S^w: they drop out of M_ij = S_i · I_c,j S_j and h_i = S_i · Σ F_j, and the cross
// products of planar vectors stay planar (Planar::crossMotion, crossForce are the 6-D ones restricted).
// So M and h are the planar recursions of chain_world.h on 3-vectors and 4-number inertias:
//   I_c,i = I_i + Σ_{children j} I_c,j,   M_ij = S_i · I_c,j S_j
//   V_i = V_p + S_i θ'_i,   A_i = A_p + V_i ×m S_i θ'_i,   F_i = I_i (A_i − g) + V_i ×* I_i V_i,   h_i = S_i · Σ F_j
// The kinematics too: each E turns about e_k alone, so the turns compose as (cos, sin) pairs
// (kinematicsPlanar). What the rest of the engine reads stays as kinematics, crbaWorld and
// biasForcesWorld leave it: X_world and S_w (whole), v_w and a_w (with their zero components). Not written: the
// 6-D I_w (the kinetic energy is kineticEnergyPlanar's instead) and f (scratch: jointLoads runs RNEA).
// Bearing loads (jointLoads, constraintReport) do not come from here.
#pragma once
#include <vector>

#include "physics/chain_sized.h"
#include "physics/chain_world.h"
#include "physics/spatial.h"

namespace dyn {

// e_k's index k if the tree moves in the plane ⊥ e_k (see the top: exact zeros and ones, checked once),
// else −1. Every hinge's axis exactly +e_k (kinematics then turns about it by rows, spatial.h turnAbout,
// leaving row k of each E exactly e_k), every placement's E with row and column k exactly e_k, every
// slide's e_k component exactly 0, gravity without an angular part; no ball joint, at least one hinge.
// (A hinge about −e_k is left to the 6-D path: kinematicsPlanar turns every hinge by +θ with S^w = +e_k.)
inline int planeNormalAxis(const TreeModel<Spatial>& model) {
  int k = -1;
  for (const auto& b : model.bodies) {
    if (b.joint == JointType::Revolute && b.coordinate_sign < 0) return -1;
    if (b.joint == JointType::Revolute && k < 0) k = b.coordinate_axis;
  }
  if (k < 0 || model.gravity[0] != 0.0 || model.gravity[1] != 0.0 || model.gravity[2] != 0.0) return -1;
  for (const auto& b : model.bodies) {
    if (b.joint == JointType::Ball) return -1;
    const Spatial::Rot& E = b.X_tree.E;
    for (int a = 0; a < 3; ++a)
      if (a != k && (E(k, a) != 0.0 || E(a, k) != 0.0)) return -1;
    if (E(k, k) != 1.0) return -1;
    if (b.joint == JointType::Prismatic && b.axis[k] != 0.0) return -1;
    if (b.joint == JointType::Revolute && b.coordinate_axis != k) return -1;
  }
  return k;
}

// A rigid-body inertia's in-plane part, world axes at the world origin: I V = (J ω + g·v, g ω + m v).
struct PlaneInertia {
  double J = 0, m = 0, gx = 0, gy = 0;
  PlaneInertia& operator+=(const PlaneInertia& o) {
    J += o.J, m += o.m, gx += o.gx, gy += o.gy;
    return *this;
  }
  DYN_INLINE Planar::Vec times(const Planar::Vec& v) const {
    return {J * v[0] + gx * v[1] + gy * v[2], gx * v[0] + m * v[1], gy * v[0] + m * v[2]};
  }
};

// The planar kernels' state beside TreeData: the plane (axis < 0: not planar) and per body its joint
// axis, world inertia, composite inertia, velocity, velocity-product acceleration and net force.
// Also each placement's turn (cos, sin) about e_k, and each body's in the world.
struct PlanarTreeData {
  int axis = -1;
  std::vector<Planar::Vec> S, v, a, f;
  std::vector<PlaneInertia> I, Ic;
  std::vector<Eigen::Vector2d> tree_turn, world_turn;
  PlanarTreeData() = default;
  explicit PlanarTreeData(const TreeModel<Spatial>& model) : axis(planeNormalAxis(model)) {
    const std::size_t n = model.bodies.size();
    S.resize(n), v.resize(n), a.resize(n), f.resize(n), I.resize(n), Ic.resize(n), world_turn.resize(n);
    const int x = axis == 2 ? 0 : axis + 1, y = x == 2 ? 0 : x + 1;
    for (const auto& b : model.bodies) tree_turn.emplace_back(axis < 0 ? 1.0 : b.X_tree.E(x, x), axis < 0 ? 0.0 : b.X_tree.E(x, y));
  }
};

namespace sized {

// kinematics<false>'s X_world and S_w of a planar tree: every E turns about e_k alone, E = R_k(φ)ᵀ
// with rows (c, s) and (−s, c) in (x, y) (spatial.h turnAbout), and the turns compose by their angles'
// sums, φ = φ_parent + φ_placement + θ (hinge): (c, s) products instead of 3 × 3 ones. The origin
// r = r_parent + E_parentᵀ r_placement (+ E_1ᵀ a θ for a slide along a, E_1 the placement's turn on
// the parent's); S^w = (e_k; r × e_k) = (e_k; r_y, −r_x, 0) for a hinge, (0; E_1ᵀ a) for a slide.
template <int N>
void kinematicsPlanar(const TreeModel<Spatial>& model, const VecIn& q, TreeData<Spatial>& data, PlanarTreeData& P) {
  const int n = N == Eigen::Dynamic ? model.dof() : N;
  const int k = P.axis, x = k == 2 ? 0 : k + 1, y = x == 2 ? 0 : x + 1;
  for (int b = 0; b < n; ++b) {
    const auto& body = model.bodies[std::size_t(b)];
    const int p = body.parent;
    const Spatial::Pos& rt = body.X_tree.r;
    // The parent's turn and origin (the world's at the root), then the placement's on them.
    double c = 1.0, s = 0.0, r[3] = {rt[0], rt[1], rt[2]};
    if (p >= 0) {
      c = P.world_turn[p][0], s = P.world_turn[p][1];
      const Spatial::Pos& rp = data.X_world[p].r;
      r[x] = rp[x] + (c * rt[x] - s * rt[y]);
      r[y] = rp[y] + (s * rt[x] + c * rt[y]);
      r[k] = rp[k] + rt[k];
    }
    if (body.X_tree.turned) {
      const double ct = P.tree_turn[b][0], st = P.tree_turn[b][1];
      const double c1 = c * ct - s * st;
      s = s * ct + c * st, c = c1;
    }
    Spatial::Vec& Sw = data.S_w[b];
    Sw.setZero();
    if (body.joint == JointType::Revolute) {
      double cq, sq;
      det::sincos(q[body.q_index], sq, cq);
      const double c1 = c * cq - s * sq;
      s = s * cq + c * sq, c = c1;
      Sw[k] = 1.0, Sw[3 + x] = r[y], Sw[3 + y] = -r[x];
    } else {  // a slide: along Eᵀ a, by θ
      const Spatial::Pos& a = body.axis;
      Sw[3 + x] = c * a[x] - s * a[y], Sw[3 + y] = s * a[x] + c * a[y];
      const double t = q[body.q_index];
      r[x] += Sw[3 + x] * t, r[y] += Sw[3 + y] * t;
    }
    P.world_turn[b] = {c, s};
    Spatial::Transform& X = data.X_world[b];
    for (int i = 0; i < 3; ++i) {
      X.r[i] = r[i];
      for (int j = 0; j < 3; ++j) X.E(i, j) = 0.0;
    }
    X.E(k, k) = 1.0, X.E(x, x) = X.E(y, y) = c, X.E(x, y) = s, X.E(y, x) = -s;
    X.turned = true;
  }
}

// M(θ) of a planar tree (planeNormalAxis ≥ 0) after kinematics: crbaWorld on (ω_z; v_x, v_y).
template <int N, class MatOut>
void crbaPlanar(const TreeModel<Spatial>& model, const TreeData<Spatial>& data, PlanarTreeData& P, MatOut& M) {
  const int n = N == Eigen::Dynamic ? model.dof() : N;
  const int k = P.axis, x = k == 2 ? 0 : k + 1, y = x == 2 ? 0 : x + 1;
  for (int b = 0; b < n; ++b) {
    const auto& body = model.bodies[std::size_t(b)];
    const Spatial::Vec& Sw = data.S_w[b];
    P.S[b] = {Sw[k], Sw[3 + x], Sw[3 + y]};
    PlaneInertia& I = P.I[b];
    if (body.massless) {
      I = P.Ic[b] = PlaneInertia{};
      continue;
    }
    // World centre of mass in the plane, c = r + Eᵀ c_body (E's row k is e_k: two terms each).
    const Spatial::Transform& X = data.X_world[b];
    const Spatial::Central& C = body.central;
    double cx = X.r[x] + C.c[x], cy = X.r[y] + C.c[y];
    if (X.turned) cx = X.r[x] + (X.E(x, x) * C.c[x] + X.E(y, x) * C.c[y]), cy = X.r[y] + (X.E(x, y) * C.c[x] + X.E(y, y) * C.c[y]);
    I.m = C.m;
    I.gx = -C.m * cy;
    I.gy = C.m * cx;
    I.J = C.Ic(k, k) + C.m * (cx * cx + cy * cy);
    P.Ic[b] = I;
  }
  for (int b = n - 1; b >= 0; --b) {
    const int p = model.bodies[std::size_t(b)].parent;
    if (p >= 0) P.Ic[p] += P.Ic[b];
  }
  fillJointSpaceInertia<Planar>(model, n, isSerialChain(model, n), P.S, [&](int j) { return P.Ic[j].times(P.S[j]); }, M);
}

// h = C θ' + G of a planar tree after crbaPlanar: biasForcesWorld on (ω_z; v_x, v_y), leaving
// data.v_w and data.a_w (their out-of-plane components zero).
template <int N, class VecOut>
void biasForcesPlanar(const TreeModel<Spatial>& model, TreeData<Spatial>& data, PlanarTreeData& P, const VecN& qd, VecOut& h) {
  using V3 = Planar::Vec;
  const int n = N == Eigen::Dynamic ? model.dof() : N;
  const int k = P.axis, x = k == 2 ? 0 : k + 1, y = x == 2 ? 0 : x + 1;
  const V3 g(0.0, model.gravity[3 + x], model.gravity[3 + y]);  // its e_k part loads the bearings alone
  auto put = [&](const V3& in, Spatial::Vec& out) {  // the 6-D vector: zero out of the plane
    out.setZero();
    out[k] = in[0], out[3 + x] = in[1], out[3 + y] = in[2];
  };
  for (int b = 0; b < n; ++b) {
    const auto& body = model.bodies[std::size_t(b)];
    const int p = body.parent;
    const V3 vJ = P.S[b] * qd[b];
    P.v[b] = p < 0 ? vJ : V3(P.v[p] + vJ);
    P.a[b] = p < 0 ? V3(V3::Zero()) : V3(P.a[p] + Planar::crossMotion(P.v[b], vJ));
    put(P.v[b], data.v_w[b]);
    put(P.a[b], data.a_w[b]);
    if (body.massless) {
      P.f[b].setZero();
      continue;
    }
    const PlaneInertia& I = P.I[b];
    P.f[b] = I.times(V3(P.a[b] - g)) + Planar::crossForce(P.v[b], I.times(P.v[b]));
  }
  for (int b = n - 1; b >= 0; --b) {
    h[b] = Planar::dot(P.S[b], P.f[b]);
    const int p = model.bodies[std::size_t(b)].parent;
    if (p >= 0) P.f[p] += P.f[b];
  }
}

// The mechanism's stages: the planar kernels for a spatial tree that moves in a plane (P.axis ≥ 0),
// else kinematics<false>, crbaWorld and biasForcesWorld.
template <int N, class S>
void kinematicsWorldOrPlanar(const TreeModel<S>& model, const VecIn& q, TreeData<S>& data, PlanarTreeData& P) {
  if constexpr (S::kDim == 6)
    if (P.axis >= 0) return kinematicsPlanar<N>(model, q, data, P);
  kinematics<false, N>(model, q, data);
}
template <int N, class S, class MatOut>
void crbaWorldOrPlanar(const TreeModel<S>& model, TreeData<S>& data, PlanarTreeData& P, MatOut& M) {
  if constexpr (S::kDim == 6)
    if (P.axis >= 0) return crbaPlanar<N>(model, data, P, M);
  crbaWorld<N>(model, data, M);
}
template <int N, class S, class VecOut>
void biasForcesWorldOrPlanar(const TreeModel<S>& model, TreeData<S>& data, PlanarTreeData& P, const VecN& qd, VecOut& h) {
  if constexpr (S::kDim == 6)
    if (P.axis >= 0) return biasForcesPlanar<N>(model, data, P, qd, h);
  biasForcesWorld<N>(model, data, qd, h);
}

}  // namespace sized

// ½ Σ V_i · I_i V_i from the last biasForcesPlanar (kineticEnergyWorld's sum on the planar parts).
inline double kineticEnergyPlanar(const PlanarTreeData& P) {
  double T = 0;
  for (std::size_t b = 0; b < P.I.size(); ++b) T += 0.5 * Planar::dot(P.v[b], P.I[b].times(P.v[b]));
  return T;
}
template <class S>
double kineticEnergyWorldOrPlanar(const TreeModel<S>& model, const TreeData<S>& data, const PlanarTreeData& P) {
  if constexpr (S::kDim == 6)
    if (P.axis >= 0) return kineticEnergyPlanar(P);
  return kineticEnergyWorld(model, data);
}

}  // namespace dyn
