// The fence (fence.h): fork, limits in the child, a pipe back, a deadline in the caller.
#include "physics/model_file/fence.h"

#include <fcntl.h>
#include <malloc.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <new>

#include "physics/model_file/model_file.h"
#include "physics/util/pipe.h"

namespace dyn::model_file::detail {
namespace {

// How the child ends: its reply follows a tag byte on the pipe.
constexpr char kReply = 'R', kRefused = 'E';
constexpr int kOutOfMemory = 97;

[[noreturn]] void outOfMemory() { ::_exit(kOutOfMemory); }

// The caller's address space now (bytes), from /proc/self/statm; 0 if unknown.
std::size_t addressSpace() {
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0;
  unsigned long pages = 0;
  const int got = std::fscanf(f, "%lu", &pages);
  std::fclose(f);
  return got == 1 ? std::size_t(pages) * std::size_t(::sysconf(_SC_PAGESIZE)) : 0;
}

// The child: limits, the work, its reply; never returns.
[[noreturn]] void child(int fd, const FenceLimits& limits, const std::function<std::string()>& work) {
  // A crash is the child's own: the caller's crash handlers (a test framework's, Python's
  // faulthandler) would report it as the caller's.
  for (int sig : {SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT, SIGTRAP, SIGXCPU, SIGPIPE}) ::signal(sig, SIG_DFL);
  // Memory: what the caller had plus the budget (a fixed total would starve a large caller).
  // (Unknown: no limit rather than one below what the caller already holds.)
  if (const std::size_t now = addressSpace(); now > 0) {
    const rlimit as{rlim_t(now + limits.memory_bytes), rlim_t(now + limits.memory_bytes)};
    ::setrlimit(RLIMIT_AS, &as);
  }
  // CPU time: SIGXCPU a second past the deadline, SIGKILL a second later (the caller kills it first).
  const rlim_t cpu = rlim_t(std::ceil(limits.seconds)) + 1;
  const rlimit c{cpu, cpu + 1};
  ::setrlimit(RLIMIT_CPU, &c);
  std::set_new_handler(outOfMemory);
  // Large blocks from fresh pages, not from the caller's heap (each reused page would be copied).
  ::mallopt(M_MMAP_THRESHOLD, 128 * 1024);
  std::string reply;
  char tag = kReply;
  try {
    reply = work();
  } catch (const std::bad_alloc&) {
    outOfMemory();
  } catch (const ModelFileError& e) {
    tag = kRefused;
    reply = e.what();
  } catch (const std::exception& e) {
    tag = kRefused;
    reply = std::string("unexpected error: ") + e.what();
  } catch (...) {
    tag = kRefused;
    reply = "unexpected error";
  }
  writeAll(fd, std::string_view(&tag, 1));
  writeAll(fd, reply);
  ::_exit(0);
}

std::string signalName(int sig) {
  const char* a = ::sigabbrev_np(sig);
  return std::to_string(sig) + (a ? std::string(", SIG") + a : std::string());
}

}  // namespace

void fenceOutOfMemory() { outOfMemory(); }

std::string fenced(const std::string& file, const std::string& who, const FenceLimits& limits, const std::function<std::string()>& work) {
  const std::string head = file + ": " + who;
  // Free heap pages go back to the system first: the child would copy each one it reuses (a page
  // shared after fork is copied on its first write), the caller fault on each after.
  ::malloc_trim(0);
  // The caller's own address-space limit (ulimit -v) below what the child would get: a child that
  // then runs out of memory (or dies of a failed allocation) met the machine's limit, not the file's.
  rlimit own{};
  const bool capped = ::getrlimit(RLIMIT_AS, &own) == 0 && own.rlim_cur != RLIM_INFINITY &&
                      own.rlim_cur < addressSpace() + limits.memory_bytes;
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw ModelFileError(head + " could not be started (no pipe: " + std::strerror(errno) + ")");
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]), ::close(fds[1]);
    throw ModelFileError(head + " could not be started (" + std::strerror(e) + ")");
  }
  if (pid == 0) {
    ::close(fds[0]);
    child(fds[1], limits, work);
  }
  ::close(fds[1]);
  // Read until the child closes the pipe, the reply (after its tag byte) passes its bound or the time is up.
  const PipeRead read = readPipe(fds[0], limits.seconds, limits.max_reply + 1, Overflow::Stop);
  const std::string& bytes = read.bytes;
  const bool late = read.late, large = read.large;
  ::close(fds[0]);
  if (late || large) ::kill(pid, SIGKILL);
  int status = 0;
  pid_t waited = 0;
  while ((waited = ::waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
  }
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%g", limits.seconds);
  if (late) throw ModelFileError(head + " took longer than " + seconds + " s on this file");
  if (large) throw ModelFileError(head + " answered with more than " + std::to_string(limits.max_reply >> 20) + " MiB");
  // waitpid fails only when the caller reaps children itself (SIGCHLD ignored): the reply then speaks.
  const bool clean = waited < 0 || (WIFEXITED(status) && WEXITSTATUS(status) == 0);
  if (clean && !bytes.empty() && bytes[0] == kReply) return bytes.substr(1);
  if (clean && !bytes.empty() && bytes[0] == kRefused) throw ModelFileError(bytes.substr(1));
  const bool starved = waited >= 0 && ((WIFEXITED(status) && WEXITSTATUS(status) == kOutOfMemory) ||
                                       (WIFSIGNALED(status) && WTERMSIG(status) != SIGXCPU));
  if (capped && starved) throw std::bad_alloc();  // the caller reports its own limit (exit 1)
  if (waited >= 0 && WIFEXITED(status) && WEXITSTATUS(status) == kOutOfMemory)
    throw ModelFileError(head + " ran out of memory on this file (limit " + std::to_string(limits.memory_bytes >> 20) + " MiB)");
  if (waited >= 0 && WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    if (sig == SIGXCPU) throw ModelFileError(head + " took longer than " + seconds + " s of CPU time on this file");
    throw ModelFileError(head + " crashed on this file (signal " + signalName(sig) + ")");
  }
  throw ModelFileError(head + " ended without an answer (exit status " + std::to_string(waited >= 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1) + ")");
}

}  // namespace dyn::model_file::detail
