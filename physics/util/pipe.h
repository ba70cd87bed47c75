// The two ends of a child's pipe, for work run in a forked child (physics/model_file/fence.h, grading/
// isolated.h): the child writes its whole answer, the parent reads until the child closes its end, a
// deadline passes or the answer grows past a bound. POSIX only; no allocation in the child beyond the
// bytes it writes.
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

namespace dyn {

// Writes every byte (retrying an interrupted write); gives up quietly when the reader is gone.
void writeAll(int fd, std::string_view bytes);

struct PipeRead {
  std::string bytes;   // what was kept of what arrived (see Overflow)
  bool late = false;   // the deadline passed before the writer closed its end
  bool large = false;  // more than max_bytes arrived
};

// What reading does past max_bytes: stop at the read that would take the bytes past it, not keeping
// that read's bytes (the caller then kills the writer); or keep draining the pipe to its end (or the
// deadline), keeping the first max_bytes.
enum class Overflow { Stop, Keep };

// Reads fd until end of file, for at most `seconds` of wall-clock time.
PipeRead readPipe(int fd, double seconds, std::size_t max_bytes, Overflow overflow);

}  // namespace dyn
