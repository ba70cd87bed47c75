// Starting another program without a shell: an argument vector handed to execvp, so a file name is
// one argument whatever it holds ($(...), quotes, spaces, newlines), never a command line to parse.
// Used where dynlab runs itself or a tool (check-lab runs grade/figure/run) and by the tests.
//   runProgram(argv, options)   fork, then in the child: chdir, redirect 0/1/2, set limits and the
//                               environment, execvp; the parent waits (with an optional deadline)
//   startProgram / waitProgram  the same in two halves, for a caller with work to do meanwhile (two
//                               programs at once, a reader on the child's pipe, a kill)
// The child does only async-signal-safe work between fork and exec (everything it needs is built
// before fork), so it is safe from a threaded process (Python, the batch grader).
#pragma once
#include <chrono>
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

// A program started and not yet waited for (startProgram), to be waited for once (waitProgram).
struct StartedProgram {
  int pid = -1;           // the child, for a signal of the caller's; -1: none to wait for
  ProcessResult result;   // what waitProgram returns when there is no child (it did not start: error)
  std::chrono::steady_clock::time_point deadline{};  // options.timeout_s after the start (none: epoch)
};

// runProgram's first half: returns once argv[0] has been exec'd (or could not be).
StartedProgram startProgram(const std::vector<std::string>& argv, const ProcessOptions& options = {});
// runProgram's second half: waits for the child (killed at its deadline) and reaps it.
ProcessResult waitProgram(StartedProgram& program);

}  // namespace dyn
