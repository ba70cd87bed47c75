// Starting another program without a shell: an argument vector handed to execvp, so a file name is
// one argument whatever it holds ($(...), quotes, spaces, newlines), never a command line to parse.
// Used where dynlab runs itself or a tool (check-lab runs grade/figure/run) and by the tests.
//   runProgram(argv, options)   fork, then in the child: chdir, redirect 0/1/2, set limits and the
//                               environment, execvp; the parent waits (with an optional deadline)
// The child does only async-signal-safe work between fork and exec (everything it needs is built
// before fork), so it is safe from a threaded process (Python, the batch grader).
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace dyn {

struct ProcessOptions {
  std::string cwd;          // the child's working folder (empty: the caller's)
  std::string stdin_file;   // empty: /dev/null
  std::string stdout_file;  // empty: /dev/null; "-": the caller's own
  std::string stderr_file;  // empty: /dev/null; "-": the caller's own
  bool append = false;      // stdout/stderr files are appended to, not truncated
  std::vector<std::pair<std::string, std::string>> set_env;  // added to (or replacing in) the caller's environment
  std::vector<std::string> unset_env;                        // removed from it
  double timeout_s = 0;           // > 0: the child is killed (SIGKILL) after this many seconds
  long long address_space = 0;    // > 0: RLIMIT_AS in bytes
  long long file_size = -1;       // ≥ 0: RLIMIT_FSIZE in bytes
};

struct ProcessResult {
  int code = -1;           // the exit status, or 128 + the signal that ended it (as a shell reports it)
  int signal = 0;          // the signal that ended it (0: it exited)
  bool timed_out = false;  // killed at the deadline
  std::string error;       // the child could not be started (fork failed, no such program): one line
  bool started() const { return error.empty(); }
};

// Runs argv[0] (looked up in PATH when it has no '/') with argv as its arguments and waits for it.
ProcessResult runProgram(const std::vector<std::string>& argv, const ProcessOptions& options = {});

}  // namespace dyn
