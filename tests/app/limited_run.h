// Running the real dynlab binary from a test with an argument vector (fork/exec, no shell), optionally
// under an address-space limit (setrlimit RLIMIT_AS in the child, as `ulimit -v` would): how it ended
// (exit code or signal), what it printed, and how long it took. Used by bounds_test and memory_limit_test.
#pragma once
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

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

// Runs DYNLAB_BIN with args in dir; address_space_bytes > 0 limits the child's address space.
// A child still running after timeout_s is killed (SIGKILL: reported as that signal).
inline Ended runDynlab(const fs::path& dir, const std::vector<std::string>& args, double address_space_bytes = 0,
                       double timeout_s = 120) {
  const fs::path out = dir / ".limited_stdout", err = dir / ".limited_stderr";
  std::vector<std::string> words{DYNLAB_BIN};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  const auto t0 = std::chrono::steady_clock::now();
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    const int o = ::open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644), e = ::open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    if (o < 0 || e < 0 || in < 0) ::_exit(126);
    ::dup2(in, 0), ::dup2(o, 1), ::dup2(e, 2);
    if (address_space_bytes > 0) {
      const rlimit limit{rlim_t(address_space_bytes), rlim_t(address_space_bytes)};
      if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(126);
    }
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  Ended r;
  int status = 0;
  for (;;) {
    const pid_t done = ::waitpid(pid, &status, WNOHANG);
    if (done == pid) break;
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > timeout_s) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      break;
    }
    ::usleep(20000);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (WIFEXITED(status)) r.code = WEXITSTATUS(status);
  else if (WIFSIGNALED(status)) r.signal = WTERMSIG(status);
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
