// Work that may end the process outright — a library that aborts or traps when an allocation or a
// thread fails, as GLib does for pango under a tight memory limit — run in a forked child, so the
// caller survives it and can say what was lost.
#pragma once
#include <functional>
#include <string>

namespace dyn {

struct IsolatedOutcome {
  enum class Kind { Done, Threw, Died } kind = Kind::Done;
  std::string message;  // Threw: the exception's what(); Died: how the child ended
};

// Runs work() in a child process (its files are the caller's; its memory is a copy). An exception
// from work() comes back as Threw with its message; std::bad_alloc, a signal, an unexpected exit,
// a failed fork or more than timeout_s seconds (the child is killed) as Died.
IsolatedOutcome runIsolated(const std::function<void()>& work, double timeout_s);

}  // namespace dyn
