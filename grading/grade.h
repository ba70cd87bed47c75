// The grader: a submission (gains as JSON, data only) → every scenario of its lab's rubric →
// Gradescope's results.json, a terminal summary, and Markdown/HTML reports with plots.
//   score of a test = points · clamp((zero − m) / (zero − full), 0, 1)   (linear partial credit)
// Every failure (bad file, unknown lab, unstable run, time budget) becomes a plain message in
// results.json with score 0 for what it touched; a results.json is always produced, valid UTF-8
// with every user-controlled text escaped for its format (grading/escape.h).
// Its extra_data.status tells a gradebook whose fault a missing grade is: "graded",
// "invalid_submission" (the student's file; they are told to fix it) or "internal_error" (the
// grader or the machine: a plot that cannot be written, an exception; never blamed on the student).
// Reproducible: grading the same file twice gives the same results.json apart from
// "execution_time"; the fingerprint (version, lab config hash, submission hash, trajectory hash)
// lets `dynlab grade --replay` check it.
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "grading/report.h"
#include "labs/config.h"
#include "labs/variants.h"

namespace dyn {

struct GradeOptions {
  std::string expected_lab;  // the assignment's lab (empty: whatever the submission names)
  std::string config_file;   // lab config (empty: the lab's default JSON)
  std::string out_dir;       // plots go to out_dir/plots/ (empty: no plots)
  PlantChoice plant;         // whose plant (labs/variants.h; default: the nominal one)
  double time_budget = 300;  // s of wall time for the whole submission
  int plot_width = 640, plot_height = 360;  // px: small enough to inline, large enough to read
  bool inline_plots = false;  // each test's plot inline in results.json (for Gradescope to show)
  // The replay hint in report.md: the dynlab command (a shell word) and where results.json will be
  // (empty: a generic hint). Paths in it are made absolute and shell-quoted.
  std::string replay_program = "dynlab", results_file;
  bool keep_runs = false;    // keep what was graded in the outcome (tools that compare or draw it)
  // Asked every 1024 steps of every run: true stops the grade as a spent time budget does (the
  // outcome is "out_of_time"); the Python module's Ctrl-C. Empty: never asked.
  std::function<bool()> stop;
};

struct GradeOutcome {
  json results;          // Gradescope results.json
  std::string report;    // readable summary for the terminal
  std::string markdown;  // report.md (plots linked as plots/*.png)
  std::string html;      // report.html (same content)
  std::string error;            // one line when the submission could not be graded (else empty)
  bool input_error = false;     // the submission's fault (results say how to fix it)
  bool internal_error = false;  // the grader's or the machine's fault
  bool out_of_time = false;     // the time budget stopped a scenario: the grade is incomplete
  // With GradeOptions::keep_runs, a graded submission's tests (values, units) and each scenario's run.
  GradeReport graded;
  std::map<std::string, ScenarioRun> runs;
  // A grade the time budget cut short is not "graded": its own status, so no reader takes it for a whole grade.
  const char* status() const {
    return input_error ? "invalid_submission" : internal_error ? "internal_error" : out_of_time ? "out_of_time" : "graded";
  }
};

// The wall-time budgets a grade takes, in s: what `--time-budget` and dynlab.grade(time_budget=)
// accept, refused by both with timeBudgetProblem's text ("expected a time budget in [1, 86400] s,
// got 0", "expected a finite time budget …, got nan"; empty for a budget in range).
inline constexpr double kMinTimeBudget = 1, kMaxTimeBudget = 86400;
std::string timeBudgetProblem(double seconds);

GradeOutcome gradeSubmission(const std::string& submission_file, const GradeOptions& options);
// A submission already in memory (the Python module's dict): graded exactly as the same JSON in a
// file; `file` names it in messages and reports.
GradeOutcome gradeSubmission(const json& submission, const std::string& file, const GradeOptions& options);

// What differs between two results.json, ignoring execution_time (empty: they match): one line per
// difference, "<JSON path>: was <old> → now <new>" (or "added, now ..." / "removed, was ...").
std::vector<std::string> compareResults(const json& expected, const json& actual);

// The command that re-grades `submission` and checks it against results_file: absolute,
// shell-quoted paths, with the --lab and --config the grade used, and --labs DIR when the graded
// lab (`lab`, when known) is outside the dynlab tree.
std::string replayCommand(const std::string& program, const std::string& results_file, const std::string& submission,
                          const GradeOptions& options, const std::string& lab = "");

// FNV-1a 64 of a string, as 16 hex digits (fingerprints and seeds).
std::string hashHex(const std::string& bytes);
std::string hashHexOf(std::uint64_t h);
// A submission's hash as the fingerprint records it and scenario seeds derive from it: of its
// canonical form (canonicalSubmission), so whitespace, key order and the spelling of a number
// (1000, 1000.0, 1e3) do not matter, and neither do the free-text answers.
std::string submissionHash(const json& submission);
// What a grade depends on, in one spelling: the submission without "answers", every number as a
// double (its dump then spells equal values alike), keys sorted.
json canonicalSubmission(const json& submission);

}  // namespace dyn
