// Zeroing and copying at a fixed instantiation's sizes (constrained_mechanism_impl.h): entry by entry
// where the sizes are known at compile time, so the few stores unroll; a memset or memcpy call costs
// more than they do, and a block copy reloads 16 bytes at a time what was just stored 8 bytes at a
// time (a store-forwarding stall). Eigen's own operations at dynamic sizes.
#pragma once
#include "physics/types.h"

namespace dyn {

// m ← the zero rows × cols matrix; stores unrolled where both sizes are fixed (a lab's instantiation:
// there a memset call costs more than the few stores).
template <int R, int C, class Mat>
void setZeroAt(Mat& m, int rows, int cols) {
  m.resize(rows, cols);
  if constexpr (R != Eigen::Dynamic && C != Eigen::Dynamic) {
    for (int c = 0; c < C; ++c)
      for (int r = 0; r < R; ++r) m(r, c) = 0.0;
  } else {
    m.setZero();
  }
}

// dst = src (its first `count` entries, when given), entry by entry where that is the fixed size N
// (unrolled), else Eigen's copy.
template <int N>
void setFixed(VecN& dst, const VecN& src, Eigen::Index count = -1) {
  if (count < 0) count = src.size();
  if constexpr (N != Eigen::Dynamic)
    if (count == N) {
      dst.resize(N);
      for (int i = 0; i < N; ++i) dst[i] = src[i];
      return;
    }
  dst = src.head(count);
}

}  // namespace dyn
