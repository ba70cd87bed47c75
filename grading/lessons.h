// A rubric's lessons checked: each pair of submissions graded by the rubric, and whether the one
// the lecture prefers leads by the stated share of the points (grading/rubric.h Lesson):
//   holds  ⇔  score(better) − score(worse) ≥ margin · maxScore
// A lesson that does not hold is a rubric that teaches the wrong thing: `dynlab lessons LAB`
// reports it, and tests/labs checks every registered lab's lessons.
#pragma once
#include <string>
#include <vector>

#include "grading/grade.h"
#include "grading/rubric.h"

namespace dyn {

struct LessonCheck {
  Lesson lesson;
  double better = 0, worse = 0, max = 0;  // the two scores and the rubric's points
  std::string error;  // a submission that could not be graded (its one-line error), else empty
  bool holds() const { return error.empty() && better - worse >= lesson.margin * max - 1e-9; }
};

// Grades every lesson's pair (paths relative to lab_dir) with `options` (its config_file: the lab's
// config holding the rubric); a file shared by several lessons is graded once.
std::vector<LessonCheck> checkLessons(const Rubric& rubric, const std::string& lab_dir, const GradeOptions& options);

}  // namespace dyn
