// Drawing in a child process; see isolated_draw.h.
#include "app/isolated_draw.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdio>
#include <stdexcept>

#include "app/progress.h"
#include "grading/isolated.h"

namespace dyn::app {

std::string memoryLimitText() {
  rlimit limit{};
  if (::getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return "";
  char text[96];
  std::snprintf(text, sizeof text, " under the address-space limit of %.0f MB (ulimit -v)", double(limit.rlim_cur) / 1e6);
  return text;
}

void drawIsolated(const std::string& what, const std::function<void()>& draw) {
  std::fflush(stdout);
  std::fflush(stderr);
  const IsolatedOutcome outcome = runIsolated(
      [&] {
        // The child: a progress bar keeps the terminal (a copy of stderr); the libraries' messages go nowhere.
        const int terminal = ::dup(STDERR_FILENO);
        if (terminal >= 0 && ::isatty(terminal)) progressFd() = terminal;
        const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        if (null >= 0) ::dup2(null, STDERR_FILENO);
        draw();
      },
      86400.0);
  if (outcome.kind == IsolatedOutcome::Kind::Done) return;
  if (outcome.kind == IsolatedOutcome::Kind::Threw) throw std::runtime_error(outcome.message);
  // Died: out of memory (std::bad_alloc), or a library's signal; under a memory limit that is its cause.
  const std::string limit = memoryLimitText();
  if (outcome.message == "ran out of memory" || !limit.empty())
    throw std::runtime_error("out of memory: drawing " + what + " stopped (" + outcome.message + ")" + limit);
  throw std::runtime_error("drawing " + what + " failed: the renderer " + outcome.message);
}

}  // namespace dyn::app
