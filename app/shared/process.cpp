// Another program started with an argument vector (app/shared/process.h): fork, set up the child, execvp;
// the parent waits for it, then or later (startProgram / waitProgram).
#include "app/shared/process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

extern char** environ;

namespace dyn {
namespace {

// The caller's environment with options' changes: NAME=VALUE strings, the names unset or set removed first.
std::vector<std::string> childEnvironment(const ProcessOptions& o) {
  auto named = [](const std::string& entry, const std::string& name) {
    return entry.size() > name.size() && entry.compare(0, name.size(), name) == 0 && entry[name.size()] == '=';
  };
  std::vector<std::string> env;
  for (char** e = environ; e && *e; ++e) {
    const std::string entry = *e;
    bool drop = false;
    for (const auto& n : o.unset_env) drop = drop || named(entry, n);
    for (const auto& [n, v] : o.set_env) drop = drop || named(entry, n);
    if (!drop) env.push_back(entry);
  }
  for (const auto& [n, v] : o.set_env) env.push_back(n + "=" + v);
  return env;
}

std::vector<char*> pointers(std::vector<std::string>& strings) {
  std::vector<char*> p;
  for (auto& s : strings) p.push_back(s.data());
  p.push_back(nullptr);
  return p;
}

// In the child, before exec: only async-signal-safe calls. A failure sends errno up `report` and exits 127.
[[noreturn]] void childFail(int report) {
  const int e = errno;
  [[maybe_unused]] const ssize_t n = ::write(report, &e, sizeof e);
  ::_exit(127);
}

// fd `target` opened on path ("" → /dev/null) for reading or writing.
void redirect(int target, const char* path, bool write, bool append, int report) {
  const int flags = write ? (O_WRONLY | O_CREAT | (append ? O_APPEND : O_TRUNC)) : O_RDONLY;
  const int fd = ::open(*path ? path : "/dev/null", flags | O_CLOEXEC, 0644);
  if (fd < 0 || ::dup2(fd, target) < 0) childFail(report);
  ::close(fd);
}

[[noreturn]] void child(const ProcessOptions& o, char* const* argv, char* const* envp, int report) {
  sigset_t none;
  ::sigemptyset(&none);
  ::sigprocmask(SIG_SETMASK, &none, nullptr);
  ::signal(SIGPIPE, SIG_DFL);
  if (!o.cwd.empty() && ::chdir(o.cwd.c_str()) != 0) childFail(report);
  redirect(0, o.stdin_file.c_str(), false, false, report);
  if (o.stdout_file != "-") redirect(1, o.stdout_file.c_str(), true, o.append, report);
  if (o.stderr_file != "-") redirect(2, o.stderr_file.c_str(), true, o.append, report);
  if (o.address_space > 0) {
    const rlimit r{rlim_t(o.address_space), rlim_t(o.address_space)};
    if (::setrlimit(RLIMIT_AS, &r) != 0) childFail(report);
  }
  if (o.file_size >= 0) {
    const rlimit r{rlim_t(o.file_size), rlim_t(o.file_size)};
    if (::setrlimit(RLIMIT_FSIZE, &r) != 0) childFail(report);
  }
  ::execvpe(argv[0], argv, envp);
  childFail(report);
}

// Waits for pid; past the deadline (when one is set) kills it. Returns the wait status.
int waitFor(pid_t pid, std::chrono::steady_clock::time_point deadline, bool& timed_out) {
  int status = 0;
  if (deadline == std::chrono::steady_clock::time_point{}) {
    while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return status;
  }
  auto pause = std::chrono::milliseconds(1);
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, WNOHANG);
    if (r == pid || (r < 0 && errno != EINTR)) return status;
    if (std::chrono::steady_clock::now() >= deadline) {
      timed_out = true;
      ::kill(pid, SIGKILL);
      while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      return status;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::milliseconds(20));
  }
}

}  // namespace

StartedProgram startProgram(const std::vector<std::string>& args, const ProcessOptions& options) {
  StartedProgram program;
  ProcessResult& result = program.result;
  if (args.empty() || args.front().empty()) {
    result.error = "no program to run";
    return program;
  }
  std::vector<std::string> arg_strings = args, env_strings = childEnvironment(options);
  const std::vector<char*> argv = pointers(arg_strings), envp = pointers(env_strings);
  int report[2];  // the child's errno if it fails before exec; closed by a successful exec
  if (::pipe2(report, O_CLOEXEC) != 0) {
    result.error = std::string("cannot open a pipe: ") + std::strerror(errno);
    return program;
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    result.error = std::string("cannot start ") + args.front() + ": " + std::strerror(errno);
    ::close(report[0]), ::close(report[1]);
    return program;
  }
  if (pid == 0) child(options, argv.data(), envp.data(), report[1]);
  ::close(report[1]);
  int child_errno = 0;
  ssize_t got;
  while ((got = ::read(report[0], &child_errno, sizeof child_errno)) < 0 && errno == EINTR) {
  }
  ::close(report[0]);
  if (options.timeout_s > 0)
    program.deadline = std::chrono::steady_clock::now() +
                       std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(options.timeout_s));
  if (got == ssize_t(sizeof child_errno)) {  // it exits 127 at once: reaped here
    bool timed_out = false;
    waitFor(pid, {}, timed_out);
    result.error = "cannot run " + args.front() + ": " + std::strerror(child_errno);
    result.code = 127;
    return program;
  }
  program.pid = pid;
  return program;
}

ProcessResult waitProgram(StartedProgram& program) {
  if (program.pid < 0) return program.result;
  ProcessResult result;
  const int status = waitFor(program.pid, program.deadline, result.timed_out);
  program.pid = -1;
  if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
    result.code = 128 + result.signal;
  } else {
    result.code = WEXITSTATUS(status);
  }
  program.result = result;
  return result;
}

ProcessResult runProgram(const std::vector<std::string>& args, const ProcessOptions& options) {
  StartedProgram program = startProgram(args, options);
  return waitProgram(program);
}

}  // namespace dyn
