// det's circular functions: sin cos tan (Cody–Waite reduction by π/2 in three 33-bit parts, then
// polynomials on [−π/4, π/4]), atan atan2 (reduction to |x| ≤ 7/16 around atan(0.5), atan(1),
// atan(1.5), then an odd polynomial), asin acos (a rational function of x²) and hypot (a double-double
// sum of squares, one Newton correction of its square root). The algorithms and the polynomial
// coefficients are those of Sun's fdlibm (published 1993, the basis of most C libraries); the code is
// written here. Accuracy measured against x87 long double: docs/determinism.md.
#include "physics/det/det.h"
#include "physics/det/sincos.h"

#include <cmath>
#include <limits>
#include <utility>

#include "physics/det/det_internal.h"

namespace det {
namespace {

using internal::biasedExponent;
using internal::bits;
using internal::DD;
using internal::fromBits;

constexpr double kPio4 = 0.7853981633974483;
constexpr double kPio2Hi = 1.5707963267948966, kPio2Lo = 6.123233995736766e-17;
constexpr double kPi = 3.141592653589793, kPiLo = 1.2246467991473532e-16;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// x = n π/2 + y0 + y1 with |y0 + y1| ≲ π/4, n returned mod 4. Exact reduction for |x| < 2^20 π/2
// (π/2's first 33-bit part times n is exact). Larger |x| are first taken modulo the double nearest 2π
// (fmod is exact): the same bits on every target, with an error of about |x|·4e-17 rad (dynlab's
// angles stay far below 10^6 rad).
int reduce(double x, double& y0, double& y1) {
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
double sinKernel(double x, double y, bool tail) {
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  const double z = x * x, w = z * z, r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6), v = z * x;
  if (!tail) return x + v * (S1 + z * r);
  return x - ((z * (0.5 * y - v * r) - y) - v * S1);
}

// cos(x + y) for |x + y| ≤ π/4.
double cosKernel(double x, double y) {
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const double z = x * x, w = z * z;
  const double r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
  const double hz = 0.5 * z, one_minus = 1.0 - hz;
  return one_minus + (((1.0 - one_minus) - hz) + (z * r - x * y));
}

// The rational function of asin and acos: (asin(√z) − √z) / √z³ ≈ R(z), 0 ≤ z ≤ 1/4.
double asinRational(double z) {
  constexpr double pS0 = 1.66666666666666657415e-01, pS1 = -3.25565818622400915405e-01,
                   pS2 = 2.01212532134862925881e-01, pS3 = -4.00555345006794114027e-02,
                   pS4 = 7.91534994289814532176e-04, pS5 = 3.47933107596021167570e-05,
                   qS1 = -2.40339491173441421878e+00, qS2 = 2.02094576023350569471e+00,
                   qS3 = -6.88283971605453293030e-01, qS4 = 7.70381505559019352791e-02;
  const double p = z * (pS0 + z * (pS1 + z * (pS2 + z * (pS3 + z * (pS4 + z * pS5)))));
  const double q = 1.0 + z * (qS1 + z * (qS2 + z * (qS3 + z * qS4)));
  return p / q;
}

// s with its low 32 bits cleared: a head whose square is exact.
double head(double s) { return fromBits(bits(s) & 0xffffffff00000000ull); }

}  // namespace

double sin(double x) {
  if (std::abs(x) <= kPio4) return std::abs(x) < 0x1p-26 ? x : sinKernel(x, 0.0, false);
  if (!std::isfinite(x)) return x - x;
  double y0, y1;
  switch (reduce(x, y0, y1)) {
    case 0: return sinKernel(y0, y1, true);
    case 1: return cosKernel(y0, y1);
    case 2: return -sinKernel(y0, y1, true);
    default: return -cosKernel(y0, y1);
  }
}

double cos(double x) {
  if (std::abs(x) <= kPio4) return std::abs(x) < 0x1p-27 ? 1.0 : cosKernel(x, 0.0);
  if (!std::isfinite(x)) return x - x;
  double y0, y1;
  switch (reduce(x, y0, y1)) {
    case 0: return cosKernel(y0, y1);
    case 1: return -sinKernel(y0, y1, true);
    case 2: return -cosKernel(y0, y1);
    default: return sinKernel(y0, y1, true);
  }
}

void sincos(double x, double& s, double& c) {
  // As sin() and cos() each take it (the same branches, kernels and reduction), the reduction once.
  if (std::abs(x) <= kPio4) {
    s = std::abs(x) < 0x1p-26 ? x : sinKernel(x, 0.0, false);
    c = std::abs(x) < 0x1p-27 ? 1.0 : cosKernel(x, 0.0);
    return;
  }
  if (!std::isfinite(x)) {
    s = c = x - x;
    return;
  }
  double y0, y1;
  const int n = reduce(x, y0, y1);
  const double sk = sinKernel(y0, y1, true), ck = cosKernel(y0, y1);
  switch (n) {
    case 0: s = sk, c = ck; break;
    case 1: s = ck, c = -sk; break;
    case 2: s = -sk, c = -ck; break;
    default: s = -ck, c = sk; break;
  }
}

double tan(double x) {
  if (std::abs(x) <= kPio4) return std::abs(x) < 0x1p-27 ? x : sinKernel(x, 0.0, false) / cosKernel(x, 0.0);
  if (!std::isfinite(x)) return x - x;
  double y0, y1;
  const int n = reduce(x, y0, y1);
  const double s = sinKernel(y0, y1, true), c = cosKernel(y0, y1);
  return n % 2 == 0 ? s / c : -c / s;
}

double atan(double x) {
  constexpr double kHi[] = {0.4636476090008061, 0.7853981633974483, 0.982793723247329, 1.5707963267948966};
  constexpr double kLo[] = {2.2698777452961687e-17, 3.061616997868383e-17, 1.3903311031230998e-17,
                            6.123233995736766e-17};
  constexpr double aT[] = {3.33333333333329318027e-01,  -1.99999999998764832476e-01, 1.42857142725034663711e-01,
                           -1.11111104054623557880e-01, 9.09088713343650656196e-02,  -7.69187620504482999495e-02,
                           6.66107313738753120669e-02,  -5.83357013379057348645e-02, 4.97687799461593236017e-02,
                           -3.65315727442169155270e-02, 1.62858201153657823623e-02};
  if (std::isnan(x)) return x + x;
  const double a = std::abs(x);
  if (a >= 0x1p66) return std::copysign(kHi[3] + kLo[3], x);
  int id = -1;
  double t = x;
  if (a < 0.4375) {
    if (a < 0x1p-27) return x;
  } else if (a < 0.6875) {
    id = 0, t = (2.0 * a - 1.0) / (2.0 + a);
  } else if (a < 1.1875) {
    id = 1, t = (a - 1.0) / (a + 1.0);
  } else if (a < 2.4375) {
    id = 2, t = (a - 1.5) / (1.0 + 1.5 * a);
  } else {
    id = 3, t = -1.0 / a;
  }
  const double z = t * t, w = z * z;
  const double s1 = z * (aT[0] + w * (aT[2] + w * (aT[4] + w * (aT[6] + w * (aT[8] + w * aT[10])))));
  const double s2 = w * (aT[1] + w * (aT[3] + w * (aT[5] + w * (aT[7] + w * aT[9]))));
  if (id < 0) return t - t * (s1 + s2);
  return std::copysign(kHi[id] - ((t * (s1 + s2) - kLo[id]) - t), x);
}

double atan2(double y, double x) {
  if (std::isnan(x) || std::isnan(y)) return x + y;
  if (x == 1.0) return atan(y);
  const int m = (std::signbit(y) ? 1 : 0) | (std::signbit(x) ? 2 : 0);
  if (y == 0.0) return m < 2 ? y : (m == 2 ? kPi : -kPi);
  if (x == 0.0) return std::signbit(y) ? -kPio2Hi : kPio2Hi;
  if (std::isinf(x)) {
    constexpr double kInfInf[] = {kPio4, -kPio4, 3.0 * kPio4, -3.0 * kPio4}, kInfFinite[] = {0.0, -0.0, kPi, -kPi};
    return std::isinf(y) ? kInfInf[m] : kInfFinite[m];
  }
  if (std::isinf(y)) return std::signbit(y) ? -kPio2Hi : kPio2Hi;
  const int gap = biasedExponent(y) - biasedExponent(x);
  double z;
  if (gap > 60) {
    return std::signbit(y) ? -kPio2Hi : kPio2Hi;  // |y/x| > 2^60
  } else if (m >= 2 && gap < -60) {
    z = 0.0;  // |y|/x tiny, x < 0
  } else {
    z = atan(std::abs(y / x));
  }
  switch (m) {
    case 0: return z;
    case 1: return -z;
    case 2: return kPi - (z - kPiLo);
    default: return (z - kPiLo) - kPi;
  }
}

double asin(double x) {
  const double a = std::abs(x);
  if (a >= 1.0) return a == 1.0 ? x * kPio2Hi + x * 0x1p-120 : kNaN;
  if (a < 0.5) return a < 0x1p-26 ? x : x + x * asinRational(x * x);
  const double z = (1.0 - a) * 0.5, s = std::sqrt(z), r = asinRational(z);
  double v;
  if (a >= 0.975) {
    v = kPio2Hi - (2.0 * (s + s * r) - kPio2Lo);
  } else {
    const double f = head(s), c = (z - f * f) / (s + f);
    v = 0.5 * kPio2Hi - (2.0 * s * r - (kPio2Lo - 2.0 * c) - (0.5 * kPio2Hi - 2.0 * f));
  }
  return std::copysign(v, x);
}

double acos(double x) {
  const double a = std::abs(x);
  if (a >= 1.0) return x == 1.0 ? 0.0 : (x == -1.0 ? 2.0 * kPio2Hi + 0x1p-120 : kNaN);
  if (a < 0.5) return a <= 0x1p-57 ? kPio2Hi + 0x1p-120 : kPio2Hi - (x - (kPio2Lo - x * asinRational(x * x)));
  if (x < 0) {
    const double z = (1.0 + x) * 0.5, s = std::sqrt(z), w = asinRational(z) * s - kPio2Lo;
    return 2.0 * (kPio2Hi - (s + w));
  }
  const double z = (1.0 - x) * 0.5, s = std::sqrt(z), f = head(s), c = (z - f * f) / (s + f);
  return 2.0 * (f + (asinRational(z) * s + c));
}

double hypot(double x, double y) {
  double a = std::abs(x), b = std::abs(y);
  if (std::isinf(a) || std::isinf(b)) return std::numeric_limits<double>::infinity();
  if (std::isnan(a) || std::isnan(b)) return a + b;
  if (a < b) std::swap(a, b);
  if (b <= a * 0x1p-60) return a;  // b²/a² below half an ulp (also b = 0)
  double scale = 1.0;
  if (a > 0x1p500) {
    a *= 0x1p-600, b *= 0x1p-600, scale = 0x1p600;
  } else if (b < 0x1p-500) {
    a *= 0x1p600, b *= 0x1p600, scale = 0x1p-600;
  }
  const DD sum = internal::ddAdd(internal::twoProd(a, a), internal::twoProd(b, b));
  const double h = std::sqrt(sum.hi);
  const DD hh = internal::twoProd(h, h);
  return (h + (((sum.hi - hh.hi) - hh.lo) + sum.lo) / (2.0 * h)) * scale;
}

}  // namespace det
