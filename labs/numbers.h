// Small number helpers every lab (and the app's panels and grading's text) share: one number
// formatted by a printf format, and the root mean square of a series.
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

// √(Σ x² / n); 0 for an empty series.
inline double rms(const std::vector<double>& x) {
  double s = 0;
  for (double v : x) s += v * v;
  return x.empty() ? 0 : std::sqrt(s / double(x.size()));
}

}  // namespace dyn
