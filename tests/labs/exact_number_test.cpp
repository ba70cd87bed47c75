// labs/numbers.h's shortestNumber (exactNumber in the web build, whose libc++ has no std::to_chars of a
// double) writes what std::to_chars writes natively: random bit patterns, short decimals, whole
// numbers, powers of two and ten, subnormals and the special values.
#include <doctest/doctest.h>

#include <cfloat>
#include <charconv>
#include <cstring>
#include <limits>
#include <random>

#include "labs/numbers.h"

namespace {

std::string toChars(double x) {
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
}

// Counts the values whose two spellings differ (the first few shown).
int mismatches(const std::vector<double>& xs) {
  int bad = 0;
  for (double x : xs) {
    const std::string want = toChars(x), got = dyn::shortestNumber(x);
    if (want == got) continue;
    if (++bad <= 5) MESSAGE(want << " written as " << got);
  }
  return bad;
}

}  // namespace

TEST_CASE("shortestNumber: the spelling of std::to_chars") {
  std::vector<double> xs = {0.0, -0.0, 1.0, -1.0, 0.1, 0.3, 2e4, 20000.000000000004, 1e9, 1e15, 1e16, 1e17, 1e21, 1e22, 1e23,
                            123456789012345680000.0, 9007199254740993.0, 5e-324, 2.2250738585072014e-308, DBL_MAX, -DBL_MAX,
                            std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::quiet_NaN(), -std::numeric_limits<double>::quiet_NaN()};
  for (int e = -330; e <= 310; ++e) xs.push_back(std::pow(10.0, e)), xs.push_back(3 * std::pow(10.0, e));
  for (int e = -1074; e <= 1023; ++e) xs.push_back(std::ldexp(1.0, e));
  std::mt19937_64 g(46);
  for (int i = 0; i < 300000; ++i) {
    const std::uint64_t bits = g();
    double x;
    std::memcpy(&x, &bits, sizeof x);
    xs.push_back(x);
    xs.push_back(double(std::int64_t(g() % 2000001) - 1000000) / std::pow(10.0, int(g() % 12)));  // short decimals
    xs.push_back(double(g() >> (g() % 64)));                                                       // whole numbers
  }
  CHECK(mismatches(xs) == 0);
}
