// A fence for untrusted parsing: work run in a forked child under a memory limit (its address space
// may grow by at most FenceLimits::memory_bytes past the caller's), a CPU-time limit and a wall-clock
// deadline (the child is killed at it), whose only way back is the bytes it returns up a pipe.
// Whatever the work does — crash, hang, run out of memory, call exit — the caller gets its bytes or
// one line (a ModelFileError naming the file), never a signal or a hang. The child only
// works, writes and _exit()s: no atexit handler, no flushed stdio buffer, nothing else of the
// caller's (safe to fork from a threaded process such as the Python module or the window).
// (grading/isolated.h does the same for work that may abort while drawing; physics may not use it. Both
// read the child's pipe with physics/util/pipe.h.)
#pragma once
#include <cstddef>
#include <functional>
#include <string>

namespace dyn::model_file::detail {

struct FenceLimits {
  double seconds = 20;                  // wall clock (and CPU time) for the work
  std::size_t memory_bytes = 1u << 30;  // address space the child may add to the caller's
  std::size_t max_reply = 256u << 20;   // bytes the work may return
};

// Runs work() in a child and returns what it returned. A ModelFileError the work throws comes back
// with its message. Otherwise one line, `file + ": " + who + ...`:
//   " crashed on this file (signal 11, SIGSEGV)", " took longer than 20 s on this file",
//   " ran out of memory on this file (limit 1024 MiB)", " ended without an answer (exit status N)".
// Except: when the caller's own address-space limit (ulimit -v) is below what the child would be
// given, a child that runs out of memory or dies by a signal met the machine's limit, not the file's,
// and fenced throws std::bad_alloc (the command's "out of memory", exit 1).
std::string fenced(const std::string& file, const std::string& who, const FenceLimits& limits, const std::function<std::string()>& work);

// For the work: ends the child as out of memory (a library's failed allocation, not operator new's).
[[noreturn]] void fenceOutOfMemory();

}  // namespace dyn::model_file::detail
