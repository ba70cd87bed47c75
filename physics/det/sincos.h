// det::sincos: det::sin(x) and det::cos(x) together, bit for bit the two functions' values, from one
// argument reduction: the tree kinematics turns each joint by both (chain_sized.h). Inline, on the
// kernels det_trig.cpp's sin and cos use (trig_kernels.h), so the same bits wherever it is compiled.
#pragma once

#include <cmath>

#include "physics/det/trig_kernels.h"

namespace det {

inline void sincos(double x, double& s, double& c) {
  using internal::cosKernel;
  using internal::sinKernel;
  if (std::abs(x) <= internal::kPio4) {
    s = std::abs(x) < 0x1p-26 ? x : sinKernel(x, 0.0, false);
    c = std::abs(x) < 0x1p-27 ? 1.0 : cosKernel(x, 0.0);
    return;
  }
  if (!std::isfinite(x)) {
    s = c = x - x;
    return;
  }
  double y0, y1;
  const int n = internal::reduce(x, y0, y1);
  const double sk = sinKernel(y0, y1, true), ck = cosKernel(y0, y1);
  switch (n) {
    case 0: s = sk, c = ck; break;
    case 1: s = ck, c = -sk; break;
    case 2: s = -sk, c = -ck; break;
    default: s = -ck, c = sk; break;
  }
}

}  // namespace det
