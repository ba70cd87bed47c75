// Running the real dynlab binary (DYNLAB_BIN) from a test, and any other program, always as an
// argument vector (app/shared/process.h: no shell, so no command line is ever built): a scratch directory
// per test case, the exit code and captured stdout/stderr, snapshots of what a command wrote, the
// trace CSVs, and the bad-input contract (exit 2, one line naming what was given, nothing written).
#pragma once
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "app/shared/process.h"

namespace dyn::test::cli {

using dyn::ProcessOptions;
using dyn::runProgram;

namespace fs = std::filesystem;

inline std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void writeFile(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

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
  int code = -1;           // the exit status, or 128 + the signal that ended it
  bool timed_out = false;  // killed at options.timeout_s
  std::string out, err;
};

// Runs argv (no shell: each element is one argument) in cwd, with stdout and stderr captured to
// files there unless o names its own. A program that cannot be started is exit 127, the reason on err.
inline Result run(const fs::path& cwd, const std::vector<std::string>& argv, ProcessOptions o = {}) {
  const fs::path out = cwd / ".stdout", err = cwd / ".stderr";
  const bool capture_out = o.stdout_file.empty(), capture_err = o.stderr_file.empty();
  if (capture_out) o.stdout_file = out.string();
  if (capture_err) o.stderr_file = err.string();
  if (o.cwd.empty()) o.cwd = cwd.string();
  const ProcessResult p = runProgram(argv, o);
  Result r;
  r.code = p.code;
  r.timed_out = p.timed_out;
  if (capture_out) r.out = readFile(out), fs::remove(out);
  if (capture_err) r.err = readFile(err), fs::remove(err);
  if (!p.started()) r.err += p.error + "\n";
  return r;
}
inline Result run(const TempDir& dir, const std::vector<std::string>& argv, const ProcessOptions& o = {}) {
  return run(dir.path, argv, o);
}

// Runs `dynlab ARGS...` in dir.
inline Result dynlab(const TempDir& dir, std::vector<std::string> args, const ProcessOptions& o = {}) {
  args.insert(args.begin(), DYNLAB_BIN);
  return run(dir, args, o);
}

// Argument lists joined: cat(base, {"--out", "x"}).
inline std::vector<std::string> cat(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// An argument list as one line, for messages (each argument as it is, separated by spaces).
inline std::string shown(const std::vector<std::string>& argv) {
  std::string s;
  for (const auto& a : argv) s += (s.empty() ? "" : " ") + a;
  return s;
}

// Options that set environment variables (NAME, VALUE) for the child.
inline ProcessOptions withEnv(std::vector<std::pair<std::string, std::string>> vars) {
  ProcessOptions o;
  o.set_env = std::move(vars);
  return o;
}

// Whether `program` is an executable file in a folder of PATH (what the shell's `command -v` finds).
inline bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::istringstream dirs(path ? path : "/usr/bin:/bin");
  for (std::string d; std::getline(dirs, d, ':');) {
    const fs::path p = fs::path(d.empty() ? "." : d) / program;
    std::error_code ec;
    if (fs::is_regular_file(p, ec) && ::access(p.c_str(), X_OK) == 0) return true;
  }
  return false;
}

// A virtual X display for windows (xvfb-run, which needs xauth too): available here?
inline bool haveXvfb() { return onPath("xvfb-run") && onPath("xauth"); }
// argv run in a fresh virtual X display of that screen size (24-bit).
inline std::vector<std::string> inXvfb(const std::vector<std::string>& argv, const std::string& screen = "1600x1000") {
  return cat({"xvfb-run", "-a", "-s", "-screen 0 " + screen + "x24"}, argv);
}

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

// The bad-input contract of a finished run r (a Result, or any type with code, out and err): exit code
// 2, nothing on stdout, one line on stderr that starts "error: " and names each of names.
template <class R>
void checkRefused(const R& r, const std::vector<std::string>& names) {
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.rfind("error: ", 0) == 0);
  for (const auto& n : names) CHECK_MESSAGE(r.err.find(n) != std::string::npos, "missing: " << n);
}

// Bad input: refused (checkRefused), and nothing written at all.
inline void checkBadInput(const TempDir& dir, const std::vector<std::string>& args, const std::vector<std::string>& names,
                          const fs::path& out) {
  INFO("dynlab ", shown(args));
  checkRefused(dynlab(dir, args), names);
  CHECK_FALSE(fs::exists(out));
}

// ffprobe's decode of a video (every frame is read, not just the header's count): the stream's
// entries (e.g. "codec_name,pix_fmt,nb_read_frames") as one CSV line, its line break trimmed.
inline std::string probeVideo(const TempDir& dir, const std::string& video, const std::string& entries) {
  const Result probe = run(dir, {"ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                                 "stream=" + entries, "-of", "csv=p=0", video});
  REQUIRE_MESSAGE(probe.code == 0, probe.err);
  std::string line = probe.out;
  line.erase(line.find_last_not_of(" \r\n") + 1);
  return line;
}

inline std::string defaultConfigText() { return readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/slider_crank.json"); }

}  // namespace dyn::test::cli
