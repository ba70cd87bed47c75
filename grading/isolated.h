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

// For a process that is itself disposable — a batch's grader, whose death costs only the submission
// it was grading, which the batch then grades again in a grader that isolates — runIsolated may run
// the work in place (no fork; no timeout: the batch's own deadline holds). Its outcome is the same
// for work that returns or throws; work that kills the process kills the caller.
void setIsolateInPlace(bool in_place);

}  // namespace dyn
