// The batch's long-lived grader processes; see batch_graders.h.
#include "app/cli/course/batch_graders.h"

#include <fcntl.h>
#include <malloc.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <string>

#include "grading/isolated.h"
#include "labs/file_write.h"
#include "labs/utf8.h"

namespace fs = std::filesystem;

namespace dyn::app::batch {
namespace {

// All n bytes through op (read or write), retrying interrupted and short transfers; false at end of
// file or on an error.
template <class Op>
bool transferAll(Op op, char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t done = op(p, n);
    if (done < 0 && errno == EINTR) continue;
    if (done <= 0) return false;
    p += done, n -= std::size_t(done);
  }
  return true;
}

bool readExactly(int fd, void* data, std::size_t n) {
  return transferAll([fd](char* p, std::size_t k) { return ::read(fd, p, k); }, static_cast<char*>(data), n);
}

bool writeExactly(int fd, const void* data, std::size_t n) {
  return transferAll([fd](char* p, std::size_t k) { return ::write(fd, p, k); }, static_cast<char*>(const_cast<void*>(data)), n);
}

// What `dynlab grade FILE --out OUT/<folder>` runs, with main()'s last word on what escapes it.
int gradeGuarded(const GradeArgs& a, const Submission& sub, const fs::path& folder) {
  GradeArgs one;
  one.submission = fs::absolute(sub.file).string();
  one.out = folder.string();
  one.time_budget = a.time_budget;
  one.lab = a.lab;
  one.config = a.config;
  one.student = sub.student;
  one.plots = a.plots;
  try {
    return gradeOne(one);
  } catch (const std::exception& e) {  // as main() reports what escapes a command
    std::string line = utf8Quotable(e.what());
    for (char& c : line)
      if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    std::fprintf(stderr, "error: internal: %s\n", line.c_str());
  } catch (...) {
    std::fprintf(stderr, "error: internal: an exception that is not a std::exception\n");
  }
  return 3;
}

// The grader's life: an index in, that submission graded (stdout and stderr into its grade.log,
// which the batch has just created), the exit code out; it ends when the batch closes the pipe.
[[noreturn]] void serve(const GradeArgs& a, const std::vector<Submission>& subs, const fs::path& out, int in, int reply) {
  const int null_fd = ::open("/dev/null", O_RDONLY);
  if (null_fd < 0 || ::dup2(null_fd, 0) < 0) ::_exit(127);
  for (std::uint32_t index = 0; readExactly(in, &index, sizeof index);) {
    if (index >= subs.size()) ::_exit(127);
    const fs::path folder = out / subs[index].folder;
    const int log_fd = ::open((folder / "grade.log").c_str(), O_WRONLY | O_APPEND | O_CLOEXEC | O_NOFOLLOW);
    if (log_fd < 0 || ::dup2(log_fd, 1) < 0 || ::dup2(log_fd, 2) < 0) ::_exit(127);
    ::close(log_fd);
    const std::int32_t code = gradeGuarded(a, subs[index], folder);
    std::fflush(nullptr);
    if (!writeExactly(reply, &code, sizeof code)) break;
  }
  ::_exit(0);
}

}  // namespace

Grader startGrader(const GradeArgs& args, const std::vector<Submission>& subs, const fs::path& out,
                   const std::vector<Grader*>& others, bool in_place) {
  int down[2], up[2];
  if (::pipe2(down, O_CLOEXEC) != 0) return {};
  if (::pipe2(up, O_CLOEXEC) != 0) {
    ::close(down[0]), ::close(down[1]);
    return {};
  }
  const pid_t parent = ::getpid();
  std::fflush(nullptr);  // nothing the batch has buffered is written again by the grader
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int err = errno;
    for (int fd : {down[0], down[1], up[0], up[1]}) ::close(fd);
    errno = err;
    return {};
  }
  if (pid == 0) {
    // The grader (the batch is single-threaded, so it may run anything). It dies with the batch, so a
    // killed batch leaves no grader writing into OUT.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(127);
    ::signal(SIGPIPE, SIG_DFL);  // as a grade run on its own has it (the batch ignores it: batch.cpp)
    ::close(down[1]), ::close(up[0]);
    for (const Grader* g : others)
      if (g->running()) ::close(g->to), ::close(g->from);
    setIsolateInPlace(in_place);
    deferDurability(true);  // the batch syncs OUT once, before its gradebook (gradeBatch)
    // A grade's large buffers (traces, plot data, PNG memory) come and go with each submission: the
    // heap keeps what it has grown to instead of giving it back and faulting it in again (the
    // system time of a batch doubled where glibc trimmed and mapped anew per submission).
    ::mallopt(M_MMAP_THRESHOLD, 32 << 20);
    ::mallopt(M_TRIM_THRESHOLD, 256 << 20);
    serve(args, subs, out, down[0], up[1]);
  }
  ::close(down[0]), ::close(up[1]);
  return {pid, down[1], up[0], in_place};
}

bool sendSubmission(const Grader& g, std::size_t index) {
  const std::uint32_t i = std::uint32_t(index);
  return writeExactly(g.to, &i, sizeof i);
}

int readExitCode(const Grader& g) {
  std::int32_t code = 0;
  return readExactly(g.from, &code, sizeof code) ? code : -1;
}

int stopGrader(Grader& g, bool kill) {
  if (kill) ::kill(g.pid, SIGKILL);
  ::close(g.to), ::close(g.from);
  int status = 0;
  while (::waitpid(g.pid, &status, 0) < 0 && errno == EINTR) {
  }
  g = {};
  return status;
}

}  // namespace dyn::app::batch
