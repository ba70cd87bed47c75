// A child's pipe: every byte written, and read back until closed, late or too large; see pipe.h.
#include "physics/util/pipe.h"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>

namespace dyn {

void writeAll(int fd, std::string_view bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += std::size_t(n);
  }
}

PipeRead readPipe(int fd, double seconds, std::size_t max_bytes, Overflow overflow) {
  PipeRead r;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    const double left = std::chrono::duration<double>(until - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      r.late = true;
      return r;
    }
    pollfd p{fd, POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min(left, 3600.0) * 1000) + 1);
    if (ready <= 0) continue;  // EINTR or time: the clock above decides
    char buf[65536];
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return r;
    const std::size_t got = std::size_t(n);
    if (r.bytes.size() + got > max_bytes) {
      r.large = true;
      if (overflow == Overflow::Stop) return r;
    }
    r.bytes.append(buf, std::min(got, max_bytes - std::min(max_bytes, r.bytes.size())));
  }
}

}  // namespace dyn
