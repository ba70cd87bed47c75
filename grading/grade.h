// The grader: a submission (gains as JSON) → the lab's rubric → Gradescope's results.json.
// Grading only looks at traces and metrics; it never touches the physics directly.
//   score of a test = points · clamp((zero − m) / (zero − full), 0, 1)   (linear partial credit)
// Every failure (bad file, unknown lab, unstable run) becomes a message in results.json with
// score 0; a results.json is always produced.
#pragma once
#include <string>

#include "labs/config.h"

namespace dyn {

struct GradeOutcome {
  json results;        // Gradescope results.json
  std::string report;  // readable summary for the terminal
  bool input_error = false;
};

GradeOutcome gradeSubmission(const std::string& submission_file);

// Linear partial credit between the full-credit and zero-credit thresholds (either order).
double partialCredit(double metric, double full, double zero);

}  // namespace dyn
