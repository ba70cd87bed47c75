// det::div (physics/det/det_complex.cpp) divides complex numbers bit for bit as g++'s operator/ does
// (libgcc's __divdc3): the screening's transfer functions keep their native bits, and WebAssembly's
// libc++, which divides by another algorithm, gets them too. Random parts over the whole exponent
// range, random bit patterns, and zeros, infinities and NaNs in every position.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "physics/det/det.h"

namespace {

using C = std::complex<double>;

bool sameBits(double x, double y) {
  if (std::isnan(x) && std::isnan(y)) return true;  // NaN payloads are not part of the promise
  return std::memcmp(&x, &y, sizeof x) == 0;
}

// Counts the quotients whose bits differ (the first few shown).
int mismatches(const std::vector<C>& ns, const std::vector<C>& ds) {
  int bad = 0;
  for (const C& n : ns)
    for (const C& d : ds) {
      const C want = n / d, got = det::div(n, d);
      if (sameBits(want.real(), got.real()) && sameBits(want.imag(), got.imag())) continue;
      if (++bad <= 5) MESSAGE(n << " / " << d << ": " << want << " vs det::div " << got);
    }
  return bad;
}

}  // namespace

TEST_CASE("det::div is g++'s complex division, bit for bit") {
  std::mt19937_64 g(42);
  std::uniform_real_distribution<double> mantissa(-1, 1), exponent(-1074, 1023), small(-30, 30);
  std::vector<C> ns, ds;
  auto bitsOf = [&] {
    const std::uint64_t b = g();
    double x;
    std::memcpy(&x, &b, sizeof x);
    return x;
  };
  for (int i = 0; i < 700; ++i) {
    ns.push_back({std::ldexp(mantissa(g), int(small(g))), std::ldexp(mantissa(g), int(small(g)))});
    ds.push_back({std::ldexp(mantissa(g), int(small(g))), std::ldexp(mantissa(g), int(small(g)))});
    ns.push_back({std::ldexp(mantissa(g), int(exponent(g))), std::ldexp(mantissa(g), int(exponent(g)))});
    ds.push_back({std::ldexp(mantissa(g), int(exponent(g))), std::ldexp(mantissa(g), int(exponent(g)))});
    ns.push_back({bitsOf(), bitsOf()});
    ds.push_back({bitsOf(), bitsOf()});
  }
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  for (double a : {0.0, -0.0, 1.0, -3.5, 1e-310, 1e308, inf, -inf, nan})
    for (double b : {0.0, -0.0, 2.0, 1e-320, -1e307, inf, nan}) ns.push_back({a, b}), ds.push_back({a, b});
  CHECK(mismatches(ns, ds) == 0);
}
