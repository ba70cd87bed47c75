// Progress bars (app/shared/progress.h): the line's format, and the real dynlab's `run --frames` and
// `figure` drawing one on a terminal (a pseudo-terminal here) and writing nothing of it anywhere
// else (tests, logs and pipes stay clean). Where no pseudo-terminal can be opened (a chroot without
// /dev/pts) the terminal half prints DYNLAB_TEST_SKIPPED, which ctest reports as skipped.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <iostream>
#include <optional>

#include "app/shared/progress.h"
#include "tests/app/cli_run.h"

using namespace dyn::app;
using namespace dyn::test::cli;

namespace {

// Runs dynlab ARGS in dir with stderr on a pseudo-terminal (stdout to a file); returns what the
// terminal received and the exit code; nothing (and a skip note) where no pseudo-terminal opens.
std::optional<std::pair<std::string, int>> onTerminal(const TempDir& dir, const std::vector<std::string>& args) {
  int master = -1, slave = -1;
  if (::openpty(&master, &slave, nullptr, nullptr, nullptr) != 0) {
    std::cout << "DYNLAB_TEST_SKIPPED: openpty failed (" << std::strerror(errno)
              << "; is /dev/pts mounted?): the progress bar on a terminal was not checked\n";
    return std::nullopt;
  }
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    ::close(master);
    const int out = ::open((dir / "terminal.stdout").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (::chdir(dir.path.c_str()) != 0 || out < 0) ::_exit(127);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(slave, STDERR_FILENO);
    std::vector<char*> argv{const_cast<char*>(DYNLAB_BIN)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(DYNLAB_BIN, argv.data());
    ::_exit(127);
  }
  ::close(slave);
  std::string seen;
  char buf[4096];
  for (ssize_t n; (n = ::read(master, buf, sizeof buf)) > 0;) seen.append(buf, std::size_t(n));  // EIO once it exits
  ::close(master);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return std::pair<std::string, int>{seen, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

}  // namespace

TEST_CASE("the progress line: what, a bar as full as the work done, the count, the percentage, the time left") {
  CHECK(progressLine("frames", 0, 60, 0.0, 10) == "frames [          ]  0/60   0 %");
  CHECK(progressLine("frames", 30, 60, 2.0, 10) == "frames [#####     ] 30/60  50 %  2 s left");
  CHECK(progressLine("frames", 60, 60, 4.0, 10) == "frames [##########] 60/60 100 %");
  CHECK(progressLine("figures", 1, 3, 0.1, 6) == "figures [##    ] 1/3  33 %");  // too early to say the time left
  CHECK(progressLine("x", 9, 4, 1.0, 4) == "x [####] 4/4 100 %");            // never past the end
  CHECK(progressLine("x", 0, 0, 1.0, 4) == "x [####] 0/0 100 %");            // nothing to do is done
}

TEST_CASE("a Progress that is not enabled writes nothing") {
  // stderr is redirected to a file by ctest: isatty is false, so the default is silent too.
  Progress silent("frames", 10, false);
  silent.set(5);
  silent.done();
  CHECK(::isatty(STDERR_FILENO) == 0);
}

TEST_CASE("dynlab run --frames and figure: a bar on a terminal, nothing of it when stderr is a file") {
  TempDir dir("progress");
  // Not a terminal: stderr stays empty, stdout is the usual report.
  const Result quiet = dynlab(dir, {"run", "slider_crank", "--duration", "0.3", "--frames", "--engine", "hand", "--out", "q"});
  INFO(quiet.out, quiet.err);
  REQUIRE(quiet.code == 0);
  CHECK(quiet.err.empty());
  const Result quiet_fig = dynlab(
      dir, {"figure", "slider_crank", "--duration", "0.3", "--still", "0.1", "--plot", "x_c", "--format", "svg", "--out", "qf"});
  REQUIRE(quiet_fig.code == 0);
  CHECK(quiet_fig.err.empty());

  // A terminal: the bar, redrawn in place (carriage returns), reaching its end, then erased.
  const auto on_run = onTerminal(dir, {"run", "slider_crank", "--duration", "0.3", "--frames", "--engine", "hand", "--out", "t"});
  if (!on_run) return;
  const auto& [run, run_code] = *on_run;
  INFO(run);
  REQUIRE(run_code == 0);
  CHECK(run.find("\rframes [") != std::string::npos);
  CHECK(run.find("] 10/10 100 %") != std::string::npos);  // 0.3 s at 30 fps: frames at 0, 1/30, ..., 0.3 s
  CHECK(run.size() >= 4);
  CHECK(run.substr(run.size() - 4) == "\r\033[K");
  CHECK(readFile(dir / "terminal.stdout").find("frames") != std::string::npos);  // the report, on stdout as before
  const auto on_fig =
      onTerminal(dir, {"figure", "slider_crank", "--duration", "0.3", "--still", "0.1", "--plot", "x_c", "--format", "svg", "--out", "tf"});
  REQUIRE(on_fig);
  const auto& [fig, fig_code] = *on_fig;
  INFO(fig);
  REQUIRE(fig_code == 0);
  CHECK(fig.find("\rsimulating hand [") != std::string::npos);
  CHECK(fig.find("\rsimulating Bullet [") != std::string::npos);
  CHECK(fig.find("\rfigures [") != std::string::npos);
  CHECK(fig.find("] 2/2 100 %") != std::string::npos);
  // Nothing but the bars on the terminal (the listing went to stdout).
  CHECK(fig.find("still_0.100.png") == std::string::npos);
}
