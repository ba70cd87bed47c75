// Small number helpers every lab (and the app's panels and grading's text) share: one number
// formatted by a printf format, a subscript, and the root mean square of a series.
#pragma once
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
