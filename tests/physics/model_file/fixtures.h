// What the model-file tests share: the example files' paths, a scratch folder to write model files
// into, seeded random states, a matrix's size.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "physics/types.h"

namespace dyn::test_model_file {

inline std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

// An empty scratch folder for the files a test writes, in the system's temporary folder, named by tag
// and this process's pid (a test keeps it in a static: made once per run).
inline std::filesystem::path scratchFolder(const std::string& tag) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / ("dynlab_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

// text written as dir/name (its folders made); returns the path.
inline std::filesystem::path writeFile(const std::filesystem::path& dir, const std::string& name, const std::string& text) {
  const std::filesystem::path p = dir / name;
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

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
