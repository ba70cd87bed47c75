// Running the real dynlab binary from a test with an argument vector (fork/exec, no shell), optionally
// under an address-space limit (setrlimit RLIMIT_AS in the child, as `ulimit -v` would): how it ended
// (exit code or signal), what it printed, and how long it took. Used by bounds_test and memory_limit_test.
#pragma once
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "app/shared/process.h"

namespace dyn::test::limited {

namespace fs = std::filesystem;

struct Ended {
  int code = -1;    // the exit code, or -1 when a signal ended it
  int signal = 0;   // the signal that ended it, or 0
  std::string out, err;
  double seconds = 0;
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs DYNLAB_BIN with args in dir (app/shared/process.h: no shell); address_space_bytes > 0 limits the
// child's address space. A child still running after timeout_s is killed (SIGKILL: reported as that signal).
inline Ended runDynlab(const fs::path& dir, const std::vector<std::string>& args, double address_space_bytes = 0,
                       double timeout_s = 120) {
  const fs::path out = dir / ".limited_stdout", err = dir / ".limited_stderr";
  std::vector<std::string> argv{DYNLAB_BIN};
  argv.insert(argv.end(), args.begin(), args.end());
  ProcessOptions o;
  o.cwd = dir.string(), o.stdout_file = out.string(), o.stderr_file = err.string(), o.timeout_s = timeout_s;
  o.address_space = static_cast<long long>(address_space_bytes);
  const auto t0 = std::chrono::steady_clock::now();
  const ProcessResult p = runProgram(argv, o);
  Ended r;
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (p.signal != 0) r.signal = p.signal;
  else r.code = p.code;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

// The number of lines of text (a last line without its newline counts).
inline int lineCount(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n + (!s.empty() && s.back() != '\n');
}

}  // namespace dyn::test::limited
