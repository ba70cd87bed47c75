// Two bodies' spatial arithmetic at once, one body a lane, for CRBA (chain_sized.h crbaWorld):
//   a body's inertia in world coordinates from its centre-of-mass form (Featherstone's Xᵀ I X):
//     c_A = r + Eᵀ c,  h = m c_A,  I_O = Eᵀ I_c E + m (|c_A|² 1 − c_A c_Aᵀ);
//   and CRBA's last pass, F_j = I_c,j S_j and M_ij = S_i · F_j (two columns j, j+1 at once).
// A lane is a GCC/Clang vector of two doubles (vector_size(16): SSE2 on x86-64, wasm SIMD, or two
// scalars where neither exists). A packed product or sum rounds each lane exactly as the scalar
// product or sum of the same two numbers (IEEE 754, round to nearest; -ffp-contract=off: never an
// FMA), so a lane that does the scalar code's operations in the scalar code's order gives its bits.
// The code below is written once on a lane type T: T = double is the one-body path (a lone body, an
// odd chain's root, a pair whose bodies take different branches or are unturned), T = Lanes2 two bodies.
#pragma once
#include "physics/spatial.h"

namespace dyn {

// Two doubles side by side, for two bodies' arithmetic at once.
typedef double Lanes2 __attribute__((vector_size(16)));

namespace lanes {

// The central inertia's transform into world coordinates, on lanes T: from the transform X = {E, r}
// (E column-major, as Eigen stores it: E(a, b) = E[a + 3 b]; `turned` false when E is the identity),
// the centre c and I_c (column-major; only its diagonal read when `diagonal`), into h = m c_A and the
// lower triangle of I_O (Io[i][j], j ≤ i). Each sum as the one-body code sums it, left to right. One
// rotation (Eᵀ I_c E, symmetric: six entries) and no cross terms in h: cheaper than turning the origin form.
template <class T>
DYN_INLINE void centralInWorld(const T* E, const T* r, const T& m, const T* c, const T* Ic, bool turned, bool diagonal, T* h,
                               T (&Io)[3][3]) {
  T cA[3], B[3][3];  // the centre in world coordinates, and I_c E
  if (turned) {
    for (int i = 0; i < 3; ++i) cA[i] = r[i] + E[3 * i] * c[0] + E[1 + 3 * i] * c[1] + E[2 + 3 * i] * c[2];
    if (diagonal) {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) B[i][j] = Ic[4 * i] * E[i + 3 * j];
    } else {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) B[i][j] = Ic[i] * E[3 * j] + Ic[i + 3] * E[1 + 3 * j] + Ic[i + 6] * E[2 + 3 * j];
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) Io[i][j] = E[3 * i] * B[0][j] + E[1 + 3 * i] * B[1][j] + E[2 + 3 * i] * B[2][j];
  } else {
    for (int i = 0; i < 3; ++i) cA[i] = r[i] + c[i];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) Io[i][j] = Ic[i + 3 * j];
  }
  for (int i = 0; i < 3; ++i) h[i] = m * cA[i];
  const T mcc = h[0] * cA[0] + h[1] * cA[1] + h[2] * cA[2];  // m |c_A|²
  // Off the diagonal the sum adds +0 as the one-body code always did (x + 0 is x but for x = −0).
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) Io[i][j] = Io[i][j] - h[i] * cA[j] + (i == j ? mcc : T{});
}

// A body's world inertia (h, I_O's lower triangle; m is the body's own) written into out, and its
// composite into comp: the same numbers, or each plus the child composite's when `child` (a serial
// chain's leaves-to-root pass: the sums Inertia::operator+= makes, without a second pass). I_O is
// written exactly symmetric, so a composite's is too (a sum of symmetric ones, entry by entry): its
// (j, i) is its (i, j), summed once. Entry by entry: an Inertia copied whole is reloaded 16 bytes at
// a time from 8-byte stores (a store-forwarding stall).
DYN_INLINE void storeInertia(double m, const double* h, const double (&Io)[3][3], Spatial::Inertia& out, Spatial::Inertia& comp,
                             const Spatial::Inertia* child) {
  out.m = m;
  comp.m = child ? m + child->m : m;
  for (int i = 0; i < 3; ++i) out.h[i] = h[i], comp.h[i] = child ? h[i] + child->h[i] : h[i];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) {
      out.Io(i, j) = out.Io(j, i) = Io[i][j];
      comp.Io(i, j) = comp.Io(j, i) = child ? Io[i][j] + child->Io(i, j) : Io[i][j];
    }
}

// One body's world inertia (T = double), into out and comp as storeInertia; a massless body's is zero.
DYN_INLINE void worldInertia(const Spatial::Transform& X, const Spatial::Central& C, bool massless, Spatial::Inertia& out,
                             Spatial::Inertia& comp, const Spatial::Inertia* child) {
  double h[3] = {0.0, 0.0, 0.0}, Io[3][3] = {};
  if (!massless) centralInWorld(X.E.data(), X.r.data(), C.m, C.c.data(), C.Ic.data(), X.turned, C.diagonal, h, Io);
  storeInertia(massless ? 0.0 : C.m, h, Io, out, comp, child);
}

// Two massive bodies' world inertias, body a in lane 0 and b in lane 1, when both are turned (X_world's
// E not the identity) and take the same branch (diagonal); their h and I_O's lower triangle into h and
// Io. False (nothing done) otherwise: the caller takes them one at a time. (An unturned pair, rare, goes
// one at a time: centralInWorld's unturned branch reads I_c's lower triangle whole, which a diagonal
// pair's lanes do not hold.)
DYN_INLINE bool worldInertiaPair(const Spatial::Transform& Xa, const Spatial::Central& Ca, const Spatial::Transform& Xb,
                                 const Spatial::Central& Cb, Lanes2* h, Lanes2 (&Io)[3][3]) {
  if (!Xa.turned || !Xb.turned || Ca.diagonal != Cb.diagonal) return false;
  Lanes2 E[9], r[3], c[3], Ic[9];
  for (int k = 0; k < 3; ++k) r[k] = Lanes2{Xa.r[k], Xb.r[k]}, c[k] = Lanes2{Ca.c[k], Cb.c[k]};
  for (int k = 0; k < 9; ++k) E[k] = Lanes2{Xa.E.data()[k], Xb.E.data()[k]};
  for (int k = 0; k < 9; ++k)
    if (!Ca.diagonal || k % 4 == 0) Ic[k] = Lanes2{Ca.Ic.data()[k], Cb.Ic.data()[k]};
  centralInWorld(E, r, Lanes2{Ca.m, Cb.m}, c, Ic, true, Ca.diagonal, h, Io);
  return true;
}

// Lane `l` of a pair's world inertia, into out and comp as storeInertia.
DYN_INLINE void storeLane(int l, double m, const Lanes2* h, const Lanes2 (&Io)[3][3], Spatial::Inertia& out, Spatial::Inertia& comp,
                          const Spatial::Inertia* child) {
  double hl[3], Iol[3][3];
  for (int i = 0; i < 3; ++i) hl[i] = h[i][l];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) Iol[i][j] = Io[i][j][l];
  storeInertia(m, hl, Iol, out, comp, child);
}

// Two columns' forces F_a = I_a S_a (lane 0), F_b = I_b S_b (lane 1): Spatial::inertiaTimes on lanes,
// the bits of inertiaTimes(Inertia, Vec) in each.
DYN_INLINE void forcePair(const Spatial::Inertia& Ia, const Spatial::Vec& Sa, const Spatial::Inertia& Ib, const Spatial::Vec& Sb,
                          Lanes2* F) {
  constexpr int K = Spatial::kInertiaNumbers;
  double A[K], B[K];
  Spatial::inertiaNumbers(Ia, A);
  Spatial::inertiaNumbers(Ib, B);
  Lanes2 I[K], s[6];
  for (int k = 0; k < K; ++k) I[k] = Lanes2{A[k], B[k]};
  for (int k = 0; k < 6; ++k) s[k] = Lanes2{Sa[k], Sb[k]};
  Spatial::inertiaTimes(I, s, F);
}

// S · F on both lanes (S the same in each): Spatial::dot's products and sums, in its order.
DYN_INLINE Lanes2 dotPair(const Spatial::Vec& S, const Lanes2* F) {
  Lanes2 s[6];
  for (int k = 0; k < 6; ++k) s[k] = Lanes2{S[k], S[k]};
  return s[0] * F[0] + s[1] * F[1] + s[2] * F[2] + s[3] * F[3] + s[4] * F[4] + s[5] * F[5];
}

}  // namespace lanes
}  // namespace dyn
