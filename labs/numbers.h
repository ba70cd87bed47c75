// Small number helpers every lab (and the app's panels and grading's text) share: one number
// formatted by a printf format or with the digits that read back exactly, a subscript, and the
// root mean square of a series.
#pragma once
#include <charconv>
#include <cmath>
#include <cstdio>
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
inline std::string exactNumber(double x) {
  char b[64];
  const auto r = std::to_chars(b, b + sizeof b, x);
  return std::string(b, r.ptr);
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
