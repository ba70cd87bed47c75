// Drawing in a child process; see isolated_draw.h.
#include "app/cli/isolated_draw.h"

#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <regex>
#include <stdexcept>

#include "app/shared/progress.h"
#include "grading/isolated.h"

namespace dyn::app {
namespace {

// What the child's libraries printed (they write to its stderr: x264's "malloc of size ... failed",
// LLVM's "out of memory"), read back from the start of the file they wrote into; at most 64 KB.
std::string printed(int fd) {
  std::string text(65536, '\0');
  const ssize_t n = fd >= 0 ? ::pread(fd, text.data(), text.size(), 0) : -1;
  text.resize(n > 0 ? std::size_t(n) : 0);
  return text;
}

}  // namespace

std::string memoryLimitText() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return "";
  char text[96];
  std::snprintf(text, sizeof text, " under the address-space limit of %.0f MiB (ulimit -v)", double(limit.rlim_cur) / 1048576.0);
  return text;
}

void drawIsolated(const std::string& what, const std::function<void()>& draw) {
  std::fflush(stdout);
  std::fflush(stderr);
  // The child's stderr goes into a file in memory (the kernel's, outside the address-space limit).
  const int log = ::memfd_create("dynlab-draw-stderr", MFD_CLOEXEC);
  const IsolatedOutcome outcome = runIsolated(
      [&] {
        // The child: a progress bar keeps the terminal (a copy of stderr); the libraries' messages go to the log.
        const int terminal = ::dup(STDERR_FILENO);
        if (terminal >= 0 && ::isatty(terminal)) progressFd() = terminal;
        if (log >= 0) ::dup2(log, STDERR_FILENO);
        draw();
      },
      86400.0);
  const std::string said = printed(log);
  if (log >= 0) ::close(log);
  if (outcome.kind == IsolatedOutcome::Kind::Done) return;
  const std::string limit = memoryLimitText();
  // Out of memory: said so by the drawing (std::bad_alloc, the renderer's GL_OUT_OF_MEMORY) or by a
  // library on its way down; or a signal under a memory limit (llvmpipe, GLib: that is their cause).
  static const std::regex memory_words("out of memory|malloc|[Cc]annot allocate|[Cc]ould not allocate|bad_alloc");
  const bool memory = outcome.message == "ran out of memory" || outcome.message.rfind("out of memory", 0) == 0 ||
                      (!limit.empty() && (outcome.kind == IsolatedOutcome::Kind::Died || std::regex_search(said, memory_words)));
  if (!memory) {
    if (outcome.kind == IsolatedOutcome::Kind::Threw) throw std::runtime_error(outcome.message);
    throw std::runtime_error("drawing " + what + " failed: the drawing process " + outcome.message);
  }
  if (outcome.message == "ran out of memory")
    throw std::runtime_error("out of memory: drawing " + what + " needed more memory than it could get" + limit);
  std::string how = outcome.kind == IsolatedOutcome::Kind::Died ? "the drawing process " + outcome.message : outcome.message;
  if (how.rfind("out of memory: ", 0) == 0) how = how.substr(15);
  throw std::runtime_error("out of memory: drawing " + what + " failed (" + how + ")" + limit);
}

}  // namespace dyn::app
