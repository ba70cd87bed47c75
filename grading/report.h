// What a grade says, in four forms: Gradescope's results.json, a terminal summary, a Markdown
// report (report.md, plots linked) and the same as HTML (report.html, via cmark-gfm, its plots
// inlined as data: URIs so the one file is the whole report).
// results.json's tests are HTML (Gradescope's "html" output format) so that each can carry its
// plot inline, where Gradescope shows it to the student.
// Everything here reads the GradeReport only; nothing is simulated.
#pragma once
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "grading/rubric.h"
#include "grading/scenario.h"
#include "labs/variants.h"

namespace dyn {

// What a simulated test's plot shows (grading/test_plot.h derives it for every lab).
struct TestPlotPlan {
  PlotRequest request;    // columns, reference, band and y label
  std::string band_unit;  // the plotted columns' unit, for the band's label
  double from = -INFINITY, to = INFINITY;  // the metric's time window: the rest is hatched
  bool equal_aspect = false;  // an x–y plot with one unit on both axes: a circle looks round
};

struct GradedTest {
  RubricTest test;
  double score = 0;
  double value = NAN;  // the measured metric (NaN when the run never produced it)
  std::string note;    // why there is no value
  std::string plot;    // relative path of its plot (plots/NN-name.png), or empty
  std::string unit;    // the metric's unit (its metric_docs or the screening's: "m", "s"; "1" or empty: none)
  std::optional<TestPlotPlan> plan;  // a simulated test's plot (a screening test has none)
  std::string plot_png;              // the plot's bytes once written (inlined in report.html, results.json)
  std::string advice;                // what to change when short of full marks (the metric's doc), or empty
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
  json answers = json::object();  // the submission's free-text "answers" (labs/submission.h), for the TA
  std::string student;        // whose plant was graded ("": the nominal plant)
  std::vector<PlantValue> plant;  // that plant's varied parameters (labs/variants.h; empty: none)
  std::string replay;         // the command that re-checks this grade (empty: a generic one)
  bool inline_plots = false;  // results.json carries each test's plot (Gradescope shows it)
  std::string plots_note;     // why there are no plots, when drawing them failed (shown to the reader)
  double score() const;
  double maxScore() const;
};

// At most this many bytes of inline plots go into one results.json (base64); later plots are left
// out with a note, so a results.json stays well under a megabyte.
constexpr std::size_t kMaxInlinePlotBytes = 600 * 1024;

json resultsJson(const GradeReport& r);
// report.md's section of the submission's written answers ("" when there are none): every line escaped.
std::string answersMarkdown(const json& answers);
std::string terminalReport(const GradeReport& r);
// report.md: each plot linked (plots/NN-name.png).
std::string markdownReport(const GradeReport& r);
// The HTML of report.md with each plot's link replaced by its bytes (a data: URI): one file.
std::string reportHtml(const GradeReport& r, const std::string& markdown, const std::string& title);
// A standalone page; markdown must already be escaped (grading/escape.h), title is plain text.
std::string renderHtml(const std::string& markdown, const std::string& title = "dynlab grade", const std::string& extra_css = "");
// The HTML of a Markdown fragment (cmark-gfm, safe mode, tables), without the page around it.
std::string renderHtmlFragment(const std::string& markdown);

// "data:image/png;base64,..." of a PNG's bytes.
std::string pngDataUri(const std::string& png);
// results.json without what only plots put there: the inline plots in its tests' output and the note
// that they could not be drawn (for --replay, which re-grades without plots).
json withoutInlinePlots(json results);

}  // namespace dyn
