// A forked child for work that may die; see isolated.h.
#include "grading/isolated.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <exception>
#include <new>

#include "physics/util/pipe.h"

namespace dyn {
namespace {

constexpr char kThrew = '\x1f';  // precedes an exception's message on the pipe
constexpr int kThrewStatus = 2, kOutOfMemoryStatus = 3;
constexpr std::size_t kMaxMessage = 65536;  // bytes of the child's message kept

// The signal's name, the same in every locale (glibc's abbreviation: "TRAP", "ABRT").
std::string abbrev(int sig) {
  const char* a = ::sigabbrev_np(sig);
  return a ? a : "?";
}

bool in_place = false;

// runIsolated's outcomes for work run in this process.
IsolatedOutcome runInPlace(const std::function<void()>& work) {
  try {
    work();
  } catch (const std::bad_alloc&) {
    return {IsolatedOutcome::Kind::Died, "ran out of memory"};
  } catch (const std::exception& e) {
    return {IsolatedOutcome::Kind::Threw, std::string(e.what()).substr(0, kMaxMessage - 1)};
  } catch (...) {
    return {IsolatedOutcome::Kind::Threw, "unknown error"};
  }
  return {};
}

}  // namespace

void setIsolateInPlace(bool yes) { in_place = yes; }

IsolatedOutcome runIsolated(const std::function<void()>& work, double timeout_s) {
  if (in_place) return runInPlace(work);
  int fds[2];
  if (::pipe(fds) != 0) return {IsolatedOutcome::Kind::Died, std::string("cannot open a pipe: ") + std::strerror(errno)};
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]), ::close(fds[1]);
    return {IsolatedOutcome::Kind::Died, std::string("cannot start a process: ") + std::strerror(e)};
  }
  if (pid == 0) {  // the child: its verdict goes up the pipe (what a library prints stays on stderr); it never returns
    ::close(fds[0]);
    try {
      work();
    } catch (const std::bad_alloc&) {  // out of memory is how the child died, not an error to report
      ::_exit(kOutOfMemoryStatus);
    } catch (const std::exception& e) {
      writeAll(fds[1], std::string(1, kThrew) + e.what());
      ::_exit(kThrewStatus);
    } catch (...) {
      writeAll(fds[1], std::string(1, kThrew) + "unknown error");
      ::_exit(kThrewStatus);
    }
    ::_exit(0);
  }

  // The parent: read until the child closes the pipe (it exits) or the time is up.
  ::close(fds[1]);
  const PipeRead read = readPipe(fds[0], timeout_s, kMaxMessage, Overflow::Keep);
  const std::string& text = read.bytes;
  const bool timed_out = read.late;
  ::close(fds[0]);
  if (timed_out) ::kill(pid, SIGKILL);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }

  if (timed_out) return {IsolatedOutcome::Kind::Died, "took longer than " + std::to_string(int(timeout_s)) + " s"};
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return {};
  if (WIFEXITED(status) && WEXITSTATUS(status) == kThrewStatus) {
    const std::size_t at = text.rfind(kThrew);
    if (at != std::string::npos) return {IsolatedOutcome::Kind::Threw, text.substr(at + 1)};
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == kOutOfMemoryStatus) return {IsolatedOutcome::Kind::Died, "ran out of memory"};
  // How it ended, in words that are the same on every machine (no pid, no time).
  return {IsolatedOutcome::Kind::Died, WIFSIGNALED(status) ? std::string("stopped by signal ") + std::to_string(WTERMSIG(status)) +
                                                                 " (SIG" + abbrev(WTERMSIG(status)) + ")"
                                                           : "exited with status " + std::to_string(WEXITSTATUS(status))};
}

}  // namespace dyn
