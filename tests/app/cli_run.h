// Running the real dynlab binary (DYNLAB_BIN) from a test: a scratch directory per test case, the
// exit code and captured stdout/stderr, snapshots of what a command wrote, the trace CSVs, and the
// bad-input contract (exit 2, one line naming what was given, nothing written).
#pragma once
#include <doctest/doctest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace dyn::test::cli {

namespace fs = std::filesystem;

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void writeFile(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

inline std::string quote(const std::string& s) { return "'" + s + "'"; }

// A fresh directory per test case, unique to this process; removed at the end.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::path(DYNLAB_TEST_TMP) / ("cli_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  fs::path operator/(const std::string& name) const { return path / name; }
};

struct Result {
  int code = -1;
  std::string out, err;
};

// Runs a shell command in dir (stdout/stderr captured to files there).
inline Result shell(const TempDir& dir, const std::string& command) {
  const fs::path out = dir / ".stdout", err = dir / ".stderr";
  const std::string cmd = "cd " + quote(dir.path.string()) + " && " + command + " >" + quote(out.string()) + " 2>" +
                          quote(err.string());
  const int status = std::system(cmd.c_str());
  Result r;
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.out = readFile(out);
  r.err = readFile(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

// Runs `dynlab ARGS` in dir.
inline Result dynlab(const TempDir& dir, const std::string& args) { return shell(dir, quote(DYNLAB_BIN) + " " + args); }

// Every regular file under dir (relative name → bytes).
inline std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files[fs::relative(e.path(), dir).string()] = readFile(e.path());
  return files;
}

struct Csv {
  std::vector<std::string> header;
  std::vector<std::vector<double>> rows;
  int col(const std::string& name) const {
    const auto it = std::find(header.begin(), header.end(), name);
    return it == header.end() ? -1 : int(it - header.begin());
  }
  double at(std::size_t r, const std::string& name) const { return rows[r][std::size_t(col(name))]; }
};

inline Csv readCsv(const fs::path& p) {
  Csv csv;
  std::istringstream in(readFile(p));
  std::string line, cell;
  REQUIRE(std::getline(in, line));
  std::istringstream h(line);
  while (std::getline(h, cell, ',')) csv.header.push_back(cell);
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::vector<double> row;
    while (std::getline(l, cell, ',')) {
      char* end = nullptr;
      row.push_back(std::strtod(cell.c_str(), &end));
      REQUIRE_MESSAGE(*end == '\0', "not a number: " << cell);
    }
    REQUIRE(row.size() == csv.header.size());
    csv.rows.push_back(row);
  }
  return csv;
}

// Bad input: exit code 2, one line on stderr naming what is given, nothing written at all.
inline void checkBadInput(const TempDir& dir, const std::string& args, const std::vector<std::string>& names,
                   const fs::path& out) {
  const Result r = dynlab(dir, args);
  INFO("dynlab ", args, "\nstderr: ", r.err);
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.rfind("error: ", 0) == 0);
  for (const auto& n : names) CHECK_MESSAGE(r.err.find(n) != std::string::npos, "missing: " << n);
  CHECK_FALSE(fs::exists(out));
}

inline std::string defaultConfigText() { return readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/slider_crank.json"); }

}  // namespace dyn::test::cli
