// Progress for long work (frames of a run, figures): one line on stderr, redrawn in place, erased
// when the work is done, so the command's own report follows as before. Shown only when stderr is
// a terminal: logs, pipes, files and tests see nothing of it.
#pragma once
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

namespace dyn::app {

// "frames [##########          ]  50/100  50 %  3 s left": what, a bar of `bar` cells, the count,
// the percentage and (once there is something to go by) the time left at the pace so far.
inline std::string progressLine(const std::string& what, std::size_t done, std::size_t total, double elapsed_s,
                                int bar = 30) {
  done = std::min(done, total);
  const double f = total ? double(done) / double(total) : 1.0;
  const int filled = int(std::floor(f * bar + 1e-9));
  std::string s = what + " [" + std::string(std::size_t(filled), '#') + std::string(std::size_t(bar - filled), ' ') + "] ";
  char b[96];
  const int digits = int(std::to_string(total).size());
  std::snprintf(b, sizeof b, "%*zu/%zu %3d %%", digits, done, total, int(std::floor(100 * f + 1e-9)));
  s += b;
  if (done > 0 && done < total && elapsed_s >= 0.5) {
    const double left = elapsed_s * double(total - done) / double(done);
    std::snprintf(b, sizeof b, "  %.0f s left", std::ceil(left));
    s += b;
  }
  return s;
}

// Where progress lines go: standard error, or in a drawing child (app/cli/isolated_draw.h, its stderr
// silenced) a copy of the terminal it had.
inline int& progressFd() {
  static int fd = STDERR_FILENO;
  return fd;
}

// A progress line for `total` units of work; set() as they are done. Silent unless enabled
// (default: stderr is a terminal). The line is erased by done() or the destructor.
class Progress {
 public:
  explicit Progress(std::string what, std::size_t total, bool enabled = ::isatty(progressFd()) == 1)
      : what_(std::move(what)), total_(total), enabled_(enabled), start_(Clock::now()) {
    set(0);
  }
  ~Progress() { done(); }
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  // Redraws at most ten times a second (and at the start and the end).
  void set(std::size_t done) {
    if (!enabled_ || finished_) return;
    const auto now = Clock::now();
    if (drawn_ && done < total_ && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    drawn_ = true;
    const std::string line = progressLine(what_, done, total_, std::chrono::duration<double>(now - start_).count());
    put("\r" + line + "\033[K");
  }
  // Erases the line.
  void done() {
    if (!enabled_ || finished_) return;
    finished_ = true;
    if (drawn_) put("\r\033[K");
  }

 private:
  using Clock = std::chrono::steady_clock;
  static void put(const std::string& s) {
    std::fflush(stderr);  // whatever the command wrote there first
    for (std::size_t done = 0; done < s.size();) {
      const ssize_t n = ::write(progressFd(), s.data() + done, s.size() - done);
      if (n <= 0) return;
      done += std::size_t(n);
    }
  }
  std::string what_;
  std::size_t total_;
  bool enabled_, drawn_ = false, finished_ = false;
  Clock::time_point start_, last_;
};

}  // namespace dyn::app
