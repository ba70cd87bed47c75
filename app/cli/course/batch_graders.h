// dynlab grade --batch's grader processes: one per job slot, a fork of the batch that grades
// submission after submission, each exactly as `dynlab grade FILE --out OUT/<folder>` would
// (gradeOne), its output into that submission's grade.log. The batch sends a submission's index
// down one pipe and reads the grade's exit code back up another. Forked once per slot, not once per
// submission: the grader keeps its warm heap, caches and page tables (a fresh fork per submission
// cost about twice the grade itself). A grader that crashes, exits or hangs takes only the
// submission it was grading with it; the batch starts a fresh one for the next (batch.cpp).
#pragma once
#include <sys/types.h>

#include <filesystem>
#include <vector>

#include "app/cli/commands.h"
#include "app/cli/course/batch.h"

namespace dyn::app::batch {

struct Grader {
  pid_t pid = -1;
  int to = -1;    // the batch's end of the pipe the grader reads submission indexes from
  int from = -1;  // the batch's end of the pipe the grader writes exit codes to (end of file: it ended)
  bool in_place = false;  // draws plots in its own process (setIsolateInPlace), not in a forked child
  bool running() const { return pid > 0; }
};

// Forks a grader for subs (graded into out/<folder>, with args' lab, config, budget and plots). The
// pipes of `others` (graders already running) are closed in it, so each grader's pipes have one
// reader and one writer. in_place: the grader draws plots in its own process (it is disposable: a
// submission it dies on is graded again by a grader that isolates them). pid < 0 when it could not be
// started (errno says why).
Grader startGrader(const GradeArgs& args, const std::vector<Submission>& subs, const std::filesystem::path& out,
                   const std::vector<Grader*>& others, bool in_place);

// Gives the grader subs[index] to grade; false when it is gone (its pipe is closed).
bool sendSubmission(const Grader& g, std::size_t index);

// The exit code the grader replied with, once `from` is readable; -1 when it ended instead.
int readExitCode(const Grader& g);

// Ends a grader (SIGKILL first when `kill`; else it exits when its pipe closes) and reaps it.
// Returns its wait status.
int stopGrader(Grader& g, bool kill);

}  // namespace dyn::app::batch
