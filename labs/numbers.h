// Small number helpers every lab (and the app's panels and grading's text) share: one number
// formatted by a printf format or with the digits that read back exactly, a subscript, and the
// root mean square of a series.
#pragma once
#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace dyn {

// x formatted by a printf format taking one double, e.g. fmt("%.3f s", t).
inline std::string fmt(const char* format, double x) {
  char b[64];
  std::snprintf(b, sizeof b, format, x);
  return b;
}

// x with the fewest digits that read back as exactly x (std::to_chars): 20000.000000000004, 1e+09,
// 0.1, nan, inf. For the value a bound message refuses: "expected a number in [0, 2e+04], got
// 20000.000000000004" shows why it is out of range where %g would print 2e+04.
inline std::string shortestNumber(double x);
inline std::string exactNumber(double x) {
#if defined(__cpp_lib_to_chars) && __cpp_lib_to_chars >= 201611L
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
#else
  return shortestNumber(x);  // libc++ 14 (emscripten 3.1.6, app/web) has no std::to_chars of a double
#endif
}

// What std::to_chars(first, last, x) writes, from printf and strtod (both correctly rounded): the
// fewest significant digits that read back as x (printf's nearest, or its neighbour: at a power of
// two the values reading back as x lie unevenly about it), then fixed or scientific notation,
// whichever is shorter (fixed on a tie; a whole number in fixed notation with all its digits).
// tests/labs/exact_number_test.cpp compares the two.
inline std::string shortestNumber(double x) {
  if (std::isnan(x)) return std::signbit(x) ? "-nan" : "nan";
  if (std::isinf(x)) return x < 0 ? "-inf" : "inf";
  if (x == 0) return std::signbit(x) ? "-0" : "0";
  const std::string sign = x < 0 ? "-" : "";
  std::string d;  // the significant digits
  int exp10 = 0;  // of the first digit
  for (int digits = 1; digits <= 17 && d.empty(); ++digits) {
    char e[40];
    std::snprintf(e, sizeof e, "%.*e", digits - 1, std::fabs(x));
    std::string m = e;
    const int at = int(m.find('e')), exp = std::atoi(e + at + 1);
    m = m.substr(0, std::size_t(at));
    m.erase(std::remove(m.begin(), m.end(), '.'), m.end());
    const unsigned long long nearest = std::stoull(m);
    for (const unsigned long long c : {nearest, nearest + 1, nearest - 1}) {
      const std::string cd = std::to_string(c);
      const int ce = exp + int(cd.size()) - digits;  // a carry (99 + 1) moves the first digit
      if (std::strtod((cd + "e" + std::to_string(ce - int(cd.size()) + 1)).c_str(), nullptr) != std::fabs(x)) continue;
      d = cd.substr(0, cd.find_last_not_of('0') + 1);
      exp10 = ce;
      break;
    }
  }
  const int n = int(d.size());
  char e[8];
  std::snprintf(e, sizeof e, "e%c%02d", exp10 < 0 ? '-' : '+', std::abs(exp10));
  const std::string sci = sign + d.substr(0, 1) + (n > 1 ? "." + d.substr(1) : "") + e;
  std::string fixed;
  if (exp10 >= n - 1) {
    char f[400];
    std::snprintf(f, sizeof f, "%.0f", x);
    fixed = f;
  } else if (exp10 >= 0) {
    fixed = sign + d.substr(0, std::size_t(exp10) + 1) + "." + d.substr(std::size_t(exp10) + 1);
  } else {
    fixed = sign + "0." + std::string(std::size_t(-exp10 - 1), '0') + d;
  }
  return fixed.size() <= sci.size() ? fixed : sci;
}

// A whole number as Unicode subscript digits (1 → "₁", 12 → "₁₂"), for labels such as τ₁; overlay and
// window fonts draw them (render/fonts.h).
inline std::string subscript(int n) {
  const std::string digits = std::to_string(n);
  std::string out;
  for (char c : digits) {
    if (c == '-') { out += "₋"; continue; }
    // U+2080 + d in UTF-8: E2 82 80+d.
    out += "\xE2\x82";
    out += char(0x80 + (c - '0'));
  }
  return out;
}

// √(Σ x² / n); 0 for an empty series.
inline double rms(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v * v;
  return x.empty() ? 0 : std::sqrt(s / double(x.size()));
}

}  // namespace dyn
