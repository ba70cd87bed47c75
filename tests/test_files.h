// Small file helpers shared by the tests: a fresh scratch directory, a whole file as bytes, and
// the text of an SVG.
#pragma once
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

namespace dyn::test {

// This test process's own folder under the system temp dir (two runs of a test at once never share
// one), removed with everything in it when the process ends.
inline const std::filesystem::path& scratchRoot() {
  struct Root {
    std::filesystem::path path = std::filesystem::temp_directory_path() / ("dynlab_test_" + std::to_string(::getpid()));
    ~Root() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Root root;
  return root.path;
}

// An empty directory in scratchRoot(), named prefix_name (removed and recreated).
inline std::filesystem::path scratchDir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path dir = scratchRoot() / (prefix + "_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// The file's bytes ("" if it cannot be read).
inline std::string readBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// An SVG's characters as text: PLplot writes each one as a numeric reference (&#x53;).
inline std::string svgText(const std::string& raw) {
  std::string text;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw.compare(i, 3, "&#x") == 0) {
      const std::size_t end = raw.find(';', i);
      text += static_cast<char>(std::stoi(raw.substr(i + 3, end - i - 3), nullptr, 16));
      i = end;
    } else {
      text += raw[i];
    }
  }
  return text;
}

}  // namespace dyn::test
