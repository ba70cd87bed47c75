// The pieces the lab contract's checks share (app/cli/authoring/lab_check.cpp and lab_check_grades.cpp):
// one check in progress (Step), running it into the report, grading a file, and the lab under check as
// every group of checks sees it. Internal to check-lab.
#pragma once
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "app/cli/authoring/lab_check.h"
#include "grading/grade.h"

namespace dyn::lab_check {

namespace fs = std::filesystem;

std::string fmt(double x);        // %.4g
std::string percent(double share);  // 12.3 %
std::string fileName(const std::string& path);
void writeFile(const fs::path& p, const std::string& text);

// One check in progress: the first failure wins; detail is said when all holds.
struct Step {
  std::string problem, detail;
  void fail(const std::string& why);
  // Records why when the condition is false; returns it.
  bool expect(bool condition, const std::string& why) {
    if (!condition) fail(why);
    return condition;
  }
};

// Runs one named check into the report; an exception is that check's failure.
void run(LabCheckReport& report, const std::string& name, const std::function<void(Step&)>& body);

// A submission with the config's default gains, and these options.
json defaultSubmission(const std::string& lab, const json& config, const json& options = json::object());
// One submission per choice of each declared option (the others left at the config's), and the defaults alone.
std::vector<json> optionSubmissions(const std::string& lab, const json& config);
// What is wrong with a grade's results.json (Gradescope's shape), or "".
std::string resultsProblem(const GradeOutcome& g);
// The share of the points a grade scored.
double scoreShare(const GradeOutcome& g);
// Grades a file and returns its outcome; a malformed results.json fails the step.
GradeOutcome graded(Step& s, const std::string& file, const GradeOptions& o);

// The lab under check, as every group of checks sees it (set up once by checkLab).
struct Checked {
  Checked(const LabEntry& e, const json& c, const LabCheckOptions& o) : entry(e), config(c), options(o) {}
  const LabEntry& entry;
  const json& config;
  const LabCheckOptions& options;
  fs::path dir;                       // options.work_dir: the checks' scratch files
  std::string config_file;            // what the grader reads: the lab's own config file, or a scratch copy
  std::string shown;                  // the name the checks give that file
  std::string lab_dir;                // where the lessons' paths and the instructor's answers start
  std::vector<std::string> examples;  // examples/*.json, then the instructor's answers (same schema)
  std::size_t shipped = 0;            // how many of examples are the students'
  GradeOptions o;                     // grades with config_file
};

// The groups of checks, in the order check-lab prints them.
void checkPhysics(const Checked& c, LabCheckReport& report);         // engines, drift, passive energy
void checkAdviceAndMetrics(const Checked& c, LabCheckReport& report);  // advice, metrics
void checkGrading(const Checked& c, LabCheckReport& report);         // grading, defaults, plots
void checkLessonPairs(const Checked& c, LabCheckReport& report);     // lessons, plants per student, doing nothing
void checkAnswers(const Checked& c, LabCheckReport& report);         // instructor, untuned
void checkOutputs(const Checked& c, LabCheckReport& report);         // render, cli, readme numbers

}  // namespace dyn::lab_check
