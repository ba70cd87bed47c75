// What a grade says, in four forms: Gradescope's results.json, a terminal summary, a Markdown
// report (report.md, plots linked) and the same as HTML (report.html, via cmark-gfm).
// Everything here reads the GradeReport only; nothing is simulated.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "grading/rubric.h"
#include "grading/scenario.h"

namespace dyn {

struct GradedTest {
  RubricTest test;
  double score = 0;
  double value = NAN;  // the measured metric (NaN when the run never produced it)
  std::string note;    // why there is no value
  std::string plot;    // relative path of its plot (plots/NN-name.png), or empty
  std::string unit;    // the metric's unit (its metric_docs or the screening's: "m", "s"; "1" or empty: none)
};

struct ScenarioSummary {
  Scenario scenario;
  double dt = 0;
  std::uint64_t trace_hash = 0;
  std::string failure;
  double failure_time = -1;
  std::vector<std::string> screen_notes;
  json metrics;
  bool out_of_time = false;
};

struct GradeReport {
  std::string lab, submission;
  std::vector<ScenarioSummary> scenarios;
  std::vector<GradedTest> tests;
  json leaderboard = json::array();
  json fingerprint;
  double score() const;
  double maxScore() const;
};

json resultsJson(const GradeReport& r);
std::string terminalReport(const GradeReport& r);
std::string markdownReport(const GradeReport& r);
// A standalone page; markdown must already be escaped (grading/escape.h), title is plain text.
std::string renderHtml(const std::string& markdown, const std::string& title = "dynlab grade", const std::string& extra_css = "");

// Writes out_dir/plots/NN-<slug>.png for every test with a plot request and records the path.
void writeTestPlots(GradeReport& r, const std::map<std::string, ScenarioRun>& runs, const std::string& out_dir);

}  // namespace dyn
