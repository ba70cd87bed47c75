// det::Normal: standard normal deviates from a std::mt19937_64 (or std::mt19937) by a transform
// written here, so a scenario's seed gives the same noise in every build (std::normal_distribution's
// algorithm is the library's: libstdc++ and libc++ turn one seed into different deviates). It is the
// polar method (Marsaglia) exactly as libstdc++ draws it, with det::log, so native grades kept their
// noise when it came in (issue 46):
//   u = g()·2^-64 (the 64-bit draw rounded to the nearest double; two 32-bit draws g1 + g2·2^32 for a
//   32-bit engine), 1 − 2^-53 if that rounds to 1; x = 2u₁ − 1, y = 2u₂ − 1, drawn again while
//   s = x² + y² > 1 or s = 0; f = √(−2 ln s / s); y·f now, x·f at the next call. docs/determinism.md.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include "physics/det/det.h"

namespace det {

class Normal {
 public:
  template <class Engine>
  double operator()(Engine& rng) {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double x, y, s;
    do {
      x = 2.0 * uniform(rng) - 1.0;
      y = 2.0 * uniform(rng) - 1.0;
      s = x * x + y * y;
    } while (s > 1.0 || s == 0.0);
    const double f = std::sqrt(-2.0 * det::log(s) / s);
    spare_ = x * f, has_spare_ = true;
    return y * f;
  }
  void reset() { has_spare_ = false; }

 private:
  // [0, 1) from 64 random bits.
  template <class Engine>
  static double uniform(Engine& rng) {
    static_assert(Engine::min() == 0 && (Engine::max() == UINT64_MAX || Engine::max() == UINT32_MAX));
    double sum = double(rng());
    if constexpr (Engine::max() == UINT32_MAX) sum += double(rng()) * 0x1p32;
    const double u = sum * 0x1p-64;
    return u >= 1.0 ? 1.0 - 0x1p-53 : u;
  }

  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace det
