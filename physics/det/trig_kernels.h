// The kernels of det's sin, cos and sincos (det_trig.cpp, sincos.h): the reduction by π/2 and the
// two polynomials on [−π/4, π/4], Sun's fdlibm algorithms and coefficients (see det_trig.cpp's top).
// In a header so that sincos inlines into the tree kinematics (chain_sized.h): a call there costs
// more than the polynomials, since every live xmm register is caller-saved in the x86-64 ABI. The
// whole tree compiles with -ffp-contract=off (CMakeLists.txt), so every copy is the same bits.
#pragma once

#include <cmath>

#include "physics/det/det_internal.h"

namespace det::internal {

constexpr double kPio4 = 0.7853981633974483;

// x = n π/2 + y0 + y1 with |y0 + y1| ≲ π/4, n returned mod 4. Exact reduction for |x| < 2^20 π/2
// (π/2's first 33-bit part times n is exact). Larger |x| are first taken modulo the double nearest 2π
// (fmod is exact): the same bits on every target, with an error of about |x|·4e-17 rad (dynlab's
// angles stay far below 10^6 rad).
inline int reduce(double x, double& y0, double& y1) {
  if (!(std::abs(x) < 1647099.0)) x = std::fmod(x, 6.283185307179586);
  constexpr double kToInt = 6755399441055744.0;  // 1.5·2^52: (v + kToInt) − kToInt rounds v to an integer
  constexpr double kInvPio2 = 0.6366197723675814;
  constexpr double kP1 = 1.5707963267341256, kP1t = 6.077100506506192e-11;
  constexpr double kP2 = 6.077100506303966e-11, kP2t = 2.0222662487959506e-21;
  constexpr double kP3 = 2.0222662487111665e-21, kP3t = 8.4784276603689e-32;
  const double fn = (x * kInvPio2 + kToInt) - kToInt;
  double r = x - fn * kP1, w = fn * kP1t;
  y0 = r - w;
  const int ex = biasedExponent(x);
  if (ex - biasedExponent(y0) > 16) {  // cancellation: subtract π/2's second part exactly too
    const double t = r;
    w = fn * kP2;
    r = t - w;
    w = fn * kP2t - ((t - r) - w);
    y0 = r - w;
    if (ex - biasedExponent(y0) > 49) {  // and its third
      const double t2 = r;
      w = fn * kP3;
      r = t2 - w;
      w = fn * kP3t - ((t2 - r) - w);
      y0 = r - w;
    }
  }
  y1 = (r - y0) - w;
  return int(static_cast<long long>(fn) & 3);  // fn is an integer below 2^21: n mod 4 without a call to fmod
}

// sin(x + y) for |x + y| ≤ π/4, y a tail below ulp(x) (used when tail is set).
inline double sinKernel(double x, double y, bool tail) {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  const double z = x * x, w = z * z, r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6), v = z * x;
  if (!tail) return x + v * (S1 + z * r);
  return x - ((z * (0.5 * y - v * r) - y) - v * S1);
}

// cos(x + y) for |x + y| ≤ π/4.
inline double cosKernel(double x, double y) {
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const double z = x * x, w = z * z;
  const double r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
  const double hz = 0.5 * z, one_minus = 1.0 - hz;
  return one_minus + (((1.0 - one_minus) - hz) + (z * r - x * y));
}

}  // namespace det::internal
