// Drawing in a child process: frames, stills and plots go through libraries that end the process
// when memory runs out instead of failing a call (llvmpipe's LLVM aborts, GLib traps when pango cannot
// start a thread, Mesa dereferences a failed allocation). Run there (grading/isolated.h), such an end
// is one line and exit 1 for the command ("out of memory: ..."), never a signal, and what the library
// printed on its way down is not shown. A progress bar (app/shared/progress.h) still reaches the terminal.
#pragma once
#include <functional>
#include <string>

namespace dyn::app {

// " under the address-space limit of 450 MB (ulimit -v)" when this process has one; "" otherwise.
std::string memoryLimitText();

// Runs draw() in a child process, its standard error kept in memory (not shown). Returns when it
// finished; throws std::runtime_error with one line otherwise: draw()'s own exception's message, or,
// when the child ran out of memory (std::bad_alloc; a signal, or a library's words for a failed
// allocation on its stderr, under an address-space limit), "out of memory: drawing WHAT ... under the
// address-space limit of N MiB (ulimit -v)".
void drawIsolated(const std::string& what, const std::function<void()>& draw);

}  // namespace dyn::app
