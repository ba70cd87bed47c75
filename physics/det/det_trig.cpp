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
#include "physics/det/trig_kernels.h"

namespace det {
namespace {

using internal::biasedExponent;
using internal::bits;
using internal::DD;
using internal::fromBits;
using internal::cosKernel;
using internal::kPio4;
using internal::reduce;
using internal::sinKernel;

constexpr double kPio2Hi = 1.5707963267948966, kPio2Lo = 6.123233995736766e-17;
constexpr double kPi = 3.141592653589793, kPiLo = 1.2246467991473532e-16;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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
