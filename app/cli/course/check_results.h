// dynlab check-results FILE: does FILE have the shape Gradescope expects of a results.json?
// run_autograder runs it on what `dynlab grade` wrote before handing the file to Gradescope, so the
// check needs nothing but dynlab (no python3 on the image).
#pragma once
#include <string>

namespace dyn::app {

// "" when `file` is a valid results.json; otherwise one line naming the file, the RFC 6901 pointer
// of the first problem and what was expected there, e.g.
//   res/results.json: /tests/0/score: expected a number, got "lots"
// Never blocks: a FIFO, a directory or a device is reported, not read.
std::string resultsProblem(const std::string& file);

// The subcommand: prints the problem as "error: ..." on stderr (exit 2) or a one-line summary (exit 0).
int checkResults(const std::string& file);

}  // namespace dyn::app
