// What the model-file tests share: the example files' paths, seeded random states, a matrix's size.
#pragma once
#include <random>
#include <string>

#include "physics/types.h"

namespace dyn::test_model_file {

inline std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

// Uniform in [−scale, scale], seeded: the same states every run.
struct Random {
  std::mt19937_64 rng{29};
  std::uniform_real_distribution<double> u{-1.0, 1.0};
  VecN vec(int n, double scale) {
    VecN v(n);
    for (int i = 0; i < n; ++i) v[i] = scale * u(rng);
    return v;
  }
};

inline double maxAbs(const MatN& a) { return a.size() ? a.cwiseAbs().maxCoeff() : 0.0; }

}  // namespace dyn::test_model_file
