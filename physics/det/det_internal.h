// det's private helpers, shared by det_trig.cpp and det_exp.cpp: bit access and double-double
// arithmetic (error-free sums and products from + − × only: exact under -ffp-contract=off, no FMA).
#pragma once

#include <bit>
#include <cstdint>
#include <cstring>

namespace det::internal {

// The same bits by memcpy where the library has no std::bit_cast (libc++ 14: emscripten 3.1.6, app/web).
#if defined(__cpp_lib_bit_cast)
inline std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }
inline double fromBits(std::uint64_t b) { return std::bit_cast<double>(b); }
#else
inline std::uint64_t bits(double x) {
  std::uint64_t b;
  std::memcpy(&b, &x, sizeof b);
  return b;
}
inline double fromBits(std::uint64_t b) {
  double x;
  std::memcpy(&x, &b, sizeof x);
  return x;
}
#endif
inline int biasedExponent(double x) { return int((bits(x) >> 52) & 0x7ff); }

// A value hi + lo with |lo| ≤ ulp(hi)/2.
struct DD {
  double hi, lo;
};

// a + b exactly, when |a| ≥ |b| (or a = 0).
inline DD fastTwoSum(double a, double b) {
  const double s = a + b;
  return {s, b - (s - a)};
}

// a + b exactly (Knuth).
inline DD twoSum(double a, double b) {
  const double s = a + b, bb = s - a;
  return {s, (a - (s - bb)) + (b - bb)};
}

// a × b exactly (Dekker, Veltkamp's split), for |a|, |b| < 2^995.
inline DD twoProd(double a, double b) {
  const double p = a * b;
  const double ca = 134217729.0 * a, ah = ca - (ca - a), al = a - ah;
  const double cb = 134217729.0 * b, bh = cb - (cb - b), bl = b - bh;
  return {p, ((ah * bh - p) + ah * bl + al * bh) + al * bl};
}

inline DD ddAdd(DD a, DD b) {
  const DD s = twoSum(a.hi, b.hi);
  return fastTwoSum(s.hi, s.lo + (a.lo + b.lo));
}

inline DD ddMul(DD a, DD b) {
  const DD p = twoProd(a.hi, b.hi);
  return fastTwoSum(p.hi, p.lo + (a.hi * b.lo + a.lo * b.hi));
}

}  // namespace det::internal
