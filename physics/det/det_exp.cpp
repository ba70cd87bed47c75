// det's exponentials and logarithms: exp (reduction by k ln 2, fdlibm's rational approximation on
// |r| ≤ ln2/2), log (fdlibm's polynomial in s = f/(2+f)), and, from a double-double logarithm written
// here (the atanh series of s with its first two terms in double-double, ~2^-64 relative), log2, log10
// and pow (exp(y ln x) with the product's tail carried); tanh from exp and a Taylor expm1.
// Accuracy measured against x87 long double: docs/determinism.md.
#include <array>
#include <cmath>
#include <limits>

#include "physics/det/det.h"
#include "physics/det/det_internal.h"

namespace det {
namespace {

using internal::bits;
using internal::DD;
using internal::ddAdd;
using internal::ddMul;
using internal::fastTwoSum;
using internal::fromBits;
using internal::twoProd;

constexpr double kLn2Hi = 0.6931471803691238, kLn2Lo = 1.9082149292705877e-10;  // hi: 32 bits
constexpr double kLn2 = 0.6931471805599453, kLn2Tail = 2.3190468138462996e-17;    // double-double ln 2
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// y · 2^n, exactly when representable (musl's scalbn steps, so subnormal results round once).
double scale(double y, int n) {
  if (n > 1023) {
    y *= 0x1p1023, n -= 1023;
    if (n > 1023) n = 1023;
  } else if (n < -1022) {
    y *= 0x1p-1022 * 0x1p53, n += 1022 - 53;
    if (n < -1022) {
      y *= 0x1p-1022 * 0x1p53, n += 1022 - 53;
      if (n < -1022) n = -1022;
    }
  }
  return y * fromBits(std::uint64_t(0x3ff + n) << 52);
}

// Positive finite x = 2^k · m with √½ ≤ m < √2 (subnormals scaled up first).
double splitLog(double x, int& k) {
  k = 0;
  if (x < 0x1p-1022) k -= 54, x *= 0x1p54;
  std::uint64_t ix = bits(x);
  std::uint32_t hx = std::uint32_t(ix >> 32) + (0x3ff00000 - 0x3fe6a09e);
  k += int(hx >> 20) - 0x3ff;
  hx = (hx & 0x000fffff) + 0x3fe6a09e;
  return fromBits(std::uint64_t(hx) << 32 | (ix & 0xffffffff));
}

// 2/(2n+1), the atanh series' coefficients (folded at compile time).
constexpr std::array<double, 13> kAtanhSeries = [] {
  std::array<double, 13> c{};
  for (std::size_t n = 0; n < c.size(); ++n) c[n] = 2.0 / double(2 * n + 1);
  return c;
}();

// ln m for √½ ≤ m < √2 in double-double: 2 atanh(s), s = (m−1)/(m+1), |s| ≤ 0.172; the series to
// s^25 (the rest < 2^-66 of the sum), 2s and (2/3)s³ carried in double-double.
DD logMantissa(double m) {
  const double f = m - 1.0;
  const DD d = fastTwoSum(2.0, f);
  const double sh = f / d.hi;
  const DD p = twoProd(sh, d.hi);
  const DD s = fastTwoSum(sh, (((f - p.hi) - p.lo) - sh * d.lo) / d.hi);
  const DD z = ddMul(s, s);
  double u = kAtanhSeries[12];
  for (std::size_t n = 11; n >= 2; --n) u = kAtanhSeries[n] + z.hi * u;  // 2/5 + z (2/7 + z (… 2/25))
  const DD t = fastTwoSum(0.6666666666666666, z.hi * u + 3.700743415417188e-17);  // 2/3 + z u
  return ddAdd({2.0 * s.hi, 2.0 * s.lo}, ddMul(ddMul(s, z), t));
}

// ln x for positive finite x in double-double: k ln 2 + ln m.
DD logDD(double x) {
  int k;
  const DD lm = logMantissa(splitLog(x, k));
  DD kl = twoProd(double(k), kLn2);
  kl.lo += double(k) * kLn2Tail;
  return ddAdd(kl, lm);
}

// What log, log2 and log10 return for x ≤ 0, ∞ and NaN; false for a positive finite x.
bool logSpecial(double x, double& out) {
  if (std::isnan(x) || x == kInf) return out = x, true;
  if (x == 0.0) return out = -kInf, true;
  if (x < 0.0) return out = kNaN, true;
  return false;
}

// e^u − 1 for |u| ≤ 1.1: Taylor to u^22 (the rest < 2^-60 of it).
constexpr std::array<double, 23> kInvFactorial = [] {
  std::array<double, 23> c{1.0};
  for (int n = 1; n <= 22; ++n) c[std::size_t(n)] = c[std::size_t(n) - 1] / n;  // folded at compile time
  return c;
}();
double expm1Small(double u) {
  double q = 0.0;
  for (int n = 22; n >= 2; --n) q = kInvFactorial[std::size_t(n)] + u * q;
  return u + (u * u) * q;
}

bool isOddInteger(double y) { return std::abs(y) < 0x1p53 && std::fmod(y, 2.0) != 0.0 && y == std::floor(y); }

// pow's IEEE 754 / C99 special cases (zeros, infinities, NaN, negative bases); false when none applies.
bool powSpecial(double x, double y, double& out) {
  if (y == 0.0 || x == 1.0) return out = 1.0, true;
  if (std::isnan(x) || std::isnan(y)) return out = x + y, true;
  const bool odd = isOddInteger(y);
  if (std::isinf(y)) {
    const double a = std::abs(x);
    return out = a == 1.0 ? 1.0 : ((a < 1.0) == (y < 0) ? kInf : 0.0), true;
  }
  if (x == 0.0 || std::isinf(x)) {
    const bool big = (x == 0.0) == (y < 0);  // 0^negative and ∞^positive are infinite
    const double v = big ? kInf : 0.0;
    return out = odd ? std::copysign(v, x) : v, true;
  }
  if (x < 0.0 && y != std::floor(y)) return out = kNaN, true;
  return false;
}

// x^n by squaring, then 1/x^|n| for n < 0: exact whenever x^|n| is (10^k for k ≤ 22: one rounding
// in 10^-k), a few roundings otherwise (measured: docs/determinism.md).
double powInteger(double x, int n) {
  double r = 1.0, b = x;
  for (unsigned m = unsigned(n < 0 ? -n : n); m != 0; m >>= 1, b *= b)
    if (m & 1u) r *= b;
  return n < 0 ? 1.0 / r : r;
}

}  // namespace

double exp(double x) {
  constexpr double kInvLn2 = 1.4426950408889634;
  constexpr double P1 = 1.66666666666666019037e-01, P2 = -2.77777777770155933842e-03,
                   P3 = 6.61375632143793436117e-05, P4 = -1.65339022054652515390e-06,
                   P5 = 4.13813679705723846039e-08;
  if (std::isnan(x)) return x;
  if (x > 709.782712893383973096) return kInf;
  if (x < -745.13321910194110842) return 0.0;
  const double a = std::abs(x);
  double hi = x, lo = 0.0;
  int k = 0;
  if (a > 0.34657359027997264) {  // ln2 / 2
    k = a >= 1.0397207708399179 ? int(kInvLn2 * x + (x < 0 ? -0.5 : 0.5)) : (x < 0 ? -1 : 1);
    hi = x - k * kLn2Hi, lo = k * kLn2Lo, x = hi - lo;
  } else if (a < 0x1p-28) {
    return 1.0 + x;
  }
  const double xx = x * x, c = x - xx * (P1 + xx * (P2 + xx * (P3 + xx * (P4 + xx * P5))));
  const double y = 1.0 + (x * c / (2.0 - c) - lo + hi);
  return k == 0 ? y : scale(y, k);
}

double log(double x) {
  constexpr double Lg1 = 6.666666666666735130e-01, Lg2 = 3.999999999940941908e-01, Lg3 = 2.857142874366239149e-01,
                   Lg4 = 2.222219843214978396e-01, Lg5 = 1.818357216161805012e-01, Lg6 = 1.531383769920937332e-01,
                   Lg7 = 1.479819860511658591e-01;
  double special;
  if (logSpecial(x, special)) return special;
  int k;
  const double f = splitLog(x, k) - 1.0, hfsq = 0.5 * f * f, s = f / (2.0 + f), z = s * s, w = z * z;
  const double t1 = w * (Lg2 + w * (Lg4 + w * Lg6)), t2 = z * (Lg1 + w * (Lg3 + w * (Lg5 + w * Lg7)));
  const double dk = k;
  return s * (hfsq + (t2 + t1)) + dk * kLn2Lo - hfsq + f + dk * kLn2Hi;
}

double log2(double x) {
  double special;
  if (logSpecial(x, special)) return special;
  int k;
  const DD r = ddMul(logMantissa(splitLog(x, k)), {1.4426950408889634, 2.0355273740931033e-17});
  return ddAdd({double(k), 0.0}, r).hi;
}

double log10(double x) {
  double special;
  if (logSpecial(x, special)) return special;
  return ddMul(logDD(x), {0.4342944819032518, 1.098319650216765e-17}).hi;
}

double pow(double x, double y) {
  double special;
  if (powSpecial(x, y, special)) return special;
  if (y == 0.5) return std::sqrt(x);
  if (y == std::floor(y) && std::abs(y) <= 64) return powInteger(x, int(y));
  const double sign = x < 0.0 && isOddInteger(y) ? -1.0 : 1.0;
  const DD l = logDD(std::abs(x));
  const double guess = y * l.hi;
  if (guess > 710.0) return sign * kInf;
  if (guess < -746.0) return sign * 0.0;
  DD p = twoProd(y, l.hi);
  p = fastTwoSum(p.hi, p.lo + y * l.lo);
  const double e = exp(p.hi);  // e^(hi + lo) = e^hi (1 + lo), |lo| ≤ 2^-43
  return sign * (e + e * p.lo);
}

double tanh(double x) {
  const double a = std::abs(x);
  if (std::isnan(x)) return x;
  if (a > 22.0) return std::copysign(1.0, x);
  if (a < 0x1p-28) return x;
  double r;
  if (a < 0.4) {  // (measured: the split with the smallest worst case, 2.3 ulp)
    const double t = expm1Small(-2.0 * a);
    r = -t / (t + 2.0);
  } else {
    r = 1.0 - 2.0 / (exp(2.0 * a) + 1.0);
  }
  return std::copysign(r, x);
}

}  // namespace det
