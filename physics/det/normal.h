// det::Normal: standard normal deviates from std::mt19937_64 by a transform written here, so a
// scenario's seed gives the same noise in every build (std::normal_distribution's algorithm is the
// library's: libstdc++ and libc++ turn one seed into different deviates). Marsaglia's polar method:
// u, v = 2·(53 random bits)·2^-53 − 1, drawn again while s = u² + v² is 0 or ≥ 1; then
// u·√(−2 ln s / s) and v·√(−2 ln s / s), the second kept for the next call. docs/determinism.md.
#pragma once

#include <cmath>
#include <random>

#include "physics/det/det.h"

namespace det {

class Normal {
 public:
  double operator()(std::mt19937_64& rng) {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = 2.0 * uniform(rng) - 1.0;
      v = 2.0 * uniform(rng) - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * det::log(s) / s);
    spare_ = v * f, has_spare_ = true;
    return u * f;
  }
  void reset() { has_spare_ = false; }

 private:
  // [0, 1) in steps of 2^-53: the top 53 bits of one draw.
  static double uniform(std::mt19937_64& rng) { return double(rng() >> 11) * 0x1p-53; }

  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace det
