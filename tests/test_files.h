// Small file helpers shared by the tests: a fresh scratch directory and a whole file as bytes.
#pragma once
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace dyn::test {

// An empty directory under the system temp dir, named prefix_name (removed and recreated).
inline std::filesystem::path scratchDir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / (prefix + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The file's bytes ("" if it cannot be read).
inline std::string readBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace dyn::test
