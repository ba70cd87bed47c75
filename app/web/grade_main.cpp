// dynlab-grade.js: the grader compiled to WebAssembly, for node (app/web/CMakeLists.txt).
//   node build/web/dynlab-grade.js LAB SUBMISSION.json
// grades SUBMISSION (whose "lab" must be LAB) as `dynlab grade SUBMISSION --lab LAB --no-plots` does and
// prints the same results.json text on stdout (the same bytes but execution_time: docs/web.md);
// the one-line error on stderr; exit code 2 for a bad submission, 3 for an internal error, 4 when
// the time budget ran out, as dynlab grade.
// The model-file labs (fivebar, puma_motion, puma_impedance) are graded from their models' descriptions,
// which scripts/web exports with the native dynlab into build/web/models/ (labs/generic/model_description.h:
// FOLDER/REL.json for the model file at TREE/REL); a model file without one is refused in one line.
#include <cstdio>
#include <string>

#include "grading/escape.h"
#include "grading/grade.h"
#include "labs/generic/model_description.h"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: node dynlab-grade.js LAB SUBMISSION.json (prints results.json)\n");
    return 2;
  }
  dyn::app::setDescriptionsFolder(DYNLAB_WEB_MODELS);
  dyn::GradeOptions options;
  options.expected_lab = argv[1];
  const dyn::GradeOutcome g = dyn::gradeSubmission(argv[2], options);
  if (!g.error.empty()) std::fprintf(stderr, "error: %s\n", g.error.c_str());
  std::fputs((dyn::dumpJson(g.results, 2) + "\n").c_str(), stdout);
  return g.input_error ? 2 : g.internal_error ? 3 : g.out_of_time ? 4 : 0;
}
