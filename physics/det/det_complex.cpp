// det::div: complex division n / d by the algorithm of g++'s runtime (libgcc's __divdc3 since gcc 12:
// Smith's method, dividing by the larger of d's parts, with scalings near the ends of the range), so
// the native build's bits stay what operator/ gave them and WebAssembly, whose libc++ divides by
// another algorithm, gets the same. + − × ÷ only. tests/physics/test_det.cpp compares it with operator/.
#include <cfloat>
#include <cmath>

#include "physics/det/det.h"

namespace det {

namespace {

constexpr double kBig = DBL_MAX / 2, kMin = DBL_MIN, kMin2 = DBL_EPSILON, kMinScale = 1 / DBL_EPSILON, kMax2 = kBig * kMin2;

// Scales a, b, p (the numerator and the larger part of the denominator) and q (the other part) as
// libgcc does before dividing by p: halved near the top of the range, raised when small.
void scale(double& a, double& b, double& p, double& q) {
  if (std::fabs(p) >= kBig) a /= 2, b /= 2, p /= 2, q /= 2;
  const bool tiny = std::fabs(p) < kMin2;
  const bool tiny_numerator = (std::fabs(a) < kMin && std::fabs(b) < kMax2 && std::fabs(p) < kMax2) ||
                              (std::fabs(b) < kMin && std::fabs(a) < kMax2 && std::fabs(p) < kMax2);
  if (tiny || tiny_numerator) a *= kMinScale, b *= kMinScale, p *= kMinScale, q *= kMinScale;
}

// The infinities and zeros a finite-arithmetic quotient turned into NaN + NaN i (C99 Annex G), from
// the parts as scaled.
std::complex<double> recovered(double a, double b, double c, double d, double x, double y) {
  if (!(std::isnan(x) && std::isnan(y))) return {x, y};
  if (c == 0.0 && d == 0.0 && (!std::isnan(a) || !std::isnan(b))) {
    const double inf = std::copysign(INFINITY, c);
    return {inf * a, inf * b};
  }
  if ((std::isinf(a) || std::isinf(b)) && std::isfinite(c) && std::isfinite(d)) {
    a = std::copysign(std::isinf(a) ? 1.0 : 0.0, a);
    b = std::copysign(std::isinf(b) ? 1.0 : 0.0, b);
    return {INFINITY * (a * c + b * d), INFINITY * (b * c - a * d)};
  }
  if ((std::isinf(c) || std::isinf(d)) && std::isfinite(a) && std::isfinite(b)) {
    c = std::copysign(std::isinf(c) ? 1.0 : 0.0, c);
    d = std::copysign(std::isinf(d) ? 1.0 : 0.0, d);
    return {0.0 * (a * c + b * d), 0.0 * (b * c - a * d)};
  }
  return {x, y};
}

}  // namespace

std::complex<double> div(std::complex<double> n, std::complex<double> den) {
  double a = n.real(), b = n.imag(), c = den.real(), d = den.imag(), x, y;
  if (std::fabs(c) < std::fabs(d)) {
    scale(a, b, d, c);
    const double ratio = c / d, denom = (c * ratio) + d;
    if (std::fabs(ratio) > kMin) {
      x = ((a * ratio) + b) / denom;
      y = ((b * ratio) - a) / denom;
    } else {
      x = ((c * (a / d)) + b) / denom;
      y = ((c * (b / d)) - a) / denom;
    }
  } else {
    scale(a, b, c, d);
    const double ratio = d / c, denom = (d * ratio) + c;
    if (std::fabs(ratio) > kMin) {
      x = ((b * ratio) + a) / denom;
      y = (b - (a * ratio)) / denom;
    } else {
      x = (a + (d * (b / c))) / denom;
      y = (b - (d * (a / c))) / denom;
    }
  }
  return recovered(a, b, c, d, x, y);  // from the scaled parts, as libgcc
}

}  // namespace det
