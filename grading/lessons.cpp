// Checking a rubric's lessons; see lessons.h.
#include "grading/lessons.h"

#include <filesystem>
#include <map>

namespace dyn {

std::vector<LessonCheck> checkLessons(const Rubric& rubric, const std::string& lab_dir, const GradeOptions& options) {
  // Each file graded once (the same gains appear in several pairs): its score and total, or its error.
  std::map<std::string, GradeOutcome> graded;
  const auto grade = [&](const std::string& relative) -> const GradeOutcome& {
    const std::string file = (std::filesystem::path(lab_dir) / relative).string();
    auto it = graded.find(file);
    if (it == graded.end()) it = graded.emplace(file, gradeSubmission(file, options)).first;
    return it->second;
  };
  std::vector<LessonCheck> out;
  for (const Lesson& lesson : rubric.lessons) {
    LessonCheck c;
    c.lesson = lesson;
    const GradeOutcome& b = grade(lesson.better);
    const GradeOutcome& w = grade(lesson.worse);
    for (const auto* g : {&b, &w})
      if (c.error.empty() && (g->input_error || g->internal_error))
        c.error = (g == &b ? lesson.better : lesson.worse) + ": " + g->error;
    if (c.error.empty()) {
      c.better = b.results.at("score").get<double>();
      c.worse = w.results.at("score").get<double>();
      c.max = rubric.maxScore();
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace dyn
