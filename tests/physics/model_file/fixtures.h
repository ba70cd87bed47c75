// What the model-file tests share: the example files' paths, a scratch folder to write model files
// into, seeded random states, a matrix's size, the one-line error a refused file gets, and two
// mechanisms' constraint rows compared.
#pragma once
#include <doctest/doctest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "physics/model_file/model_file.h"
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

// The error model_file::load refuses file with ("" when it loads), checked to be one line that starts
// with the file's path; seconds (when asked): how long the loader took.
inline std::string errorOf(const std::filesystem::path& file, double* seconds = nullptr) {
  const auto t0 = std::chrono::steady_clock::now();
  std::string what;
  try {
    model_file::load(file.string());
  } catch (const model_file::ModelFileError& e) {
    what = e.what();
  }
  if (seconds) *seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  CHECK(what.find('\n') == std::string::npos);
  CHECK(what.rfind(file.string() + ": ", 0) == 0);
  return what;
}

// φ and the constraint rows G of two mechanisms, each at its own coordinates, agree to tol; both have
// `rows` rows.
template <class A, class B>
void checkSameConstraints(A& a, const VecN& qa, B& b, const VecN& qb, long rows, double tol = 1e-12) {
  VecN phi_a, phi_b;
  MatN G_a, G_b;
  a.constraint(qa, phi_a, G_a);
  b.constraint(qb, phi_b, G_b);
  REQUIRE(G_a.rows() == rows);
  REQUIRE(G_b.rows() == rows);
  CHECK(maxAbs(phi_a - phi_b) < tol);
  CHECK(maxAbs(G_a - G_b) < tol);
}

}  // namespace dyn::test_model_file
