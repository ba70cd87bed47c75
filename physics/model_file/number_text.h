// A number as the model-file loader's messages and notes write it: printf's %g to a given count of
// significant digits (6: %g's own; 3 for the drawing's notes; 17 to round-trip a double).
#pragma once
#include <cstdio>
#include <string>

namespace dyn::model_file::detail {

inline std::string numberText(double x, int digits = 6) {
  char b[40];
  std::snprintf(b, sizeof b, "%.*g", digits, x);
  return b;
}

}  // namespace dyn::model_file::detail
