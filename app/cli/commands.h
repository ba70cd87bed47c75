// The dynlab subcommands. Each returns the process exit code:
//   0 success, 1 a run or write failed (a diverging run stopped by the watchdog included),
//   2 bad input (nothing written; a grade still writes its score-0 results.json),
//   3 internal error (the grader or the machine; caught at the top of main, or reported in
//     results.json when it could be written), 4 a grade cut short by its time budget.
#pragma once
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "labs/generic/model_lab.h"
#include "labs/lab.h"
#include "labs/run.h"

namespace dyn::app {

struct RunArgs {
  std::string lab, config, gains, out, engine = "both", scenario;
  std::string student;  // whose plant (labs/variants.h; empty: the nominal one)
  bool video = false, frames = false;
  std::optional<double> duration;
  // A model file's run only (dynlab model's options): constant torques JOINT=VALUE, loops beside it.
  std::vector<std::string> torques;
  std::string loops;
  ModelFileFlags model_files;  // --ignore-contacts, --package-path
  std::optional<double> dt;    // --dt (s; default: the file's <option timestep>)
};

struct GradeArgs {
  std::string submission, out = "out/grade", lab, config, replay, batch;
  std::string student;  // whose plant (grading/student.h); --batch: each submission's own ID instead
  std::string roster;   // --batch: a CSV of file or folder name → student ID
  std::string student_from;  // Gradescope's submission_metadata.json: its submitter is the student
  double time_budget = 300;  // s of wall time per submission
  bool plots = true;
  bool inline_plots = false;  // each test's plot inline in results.json (the Gradescope autograder)
  int jobs = 1;
};

struct UiArgs {
  std::string lab, config, gains, scenario, student;
  std::vector<std::string> extra;  // passed on to dynlab-ui as they are
};

struct FigureArgs {
  std::string lab, config, out, engine = "both", format = "pdf", title, scenario, student;
  std::vector<std::string> gains;  // none or one: one run; several: each a run, overlaid on every plot
  std::string size;              // WxH of stills and plots (empty: 1920x1080 stills, 800x450 plots)
  std::string y_scale = "auto";  // plots: auto (log when the data span decades), linear or log
  double font_scale = 1.0;       // plots' text size
  std::vector<std::string> plots;  // each "col,col,...": one plot
  std::vector<double> stills;      // simulated times (s)
  std::optional<double> duration;
  bool overlay = true;
  ModelFileFlags model_files;  // a model file's --ignore-contacts, --package-path
};

// dynlab compare A B: two submissions of one lab graded by the same rubric, side by side.
struct CompareArgs {
  std::string a, b, out = "out/compare", lab, config;
  double time_budget = 300;  // s of wall time per submission
  bool plots = true;
};

// dynlab lessons LAB: the rubric's lesson pairs graded, and whether each ranks as the lecture says.
struct LessonsArgs {
  std::string lab, config;
  double time_budget = 300;  // s of wall time per submission
};

// dynlab check-lab LAB: the every-lab contract's checks on one lab (app/cli/authoring/lab_check.h).
struct CheckLabArgs {
  std::string lab;
  bool skip_cli = false;  // no dynlab figure/run/grade subprocesses
};

// dynlab new-lab NAME --from LAB: a data-defined lab copied from another (app/cli/authoring/new_lab.cpp).
struct NewLabArgs {
  std::string name, from;
  // --labs: the first is the folder of lab folders written into (default: the first DYNLAB_LABS
  // folder, else the dynlab tree's labs/); all are searched for --from (app/cli/lab_options.h)
  std::vector<std::string> labs;
};

struct BenchArgs {
  bool json = false;
  int steps = 4000, frames = 60;
  std::string lab;         // empty: every lab
  bool scaling = false;    // the chain-length sweep instead (app/cli/bench/bench_scaling.cpp)
  std::string out;         // --scaling: where scaling.csv and scaling.png go (default out/bench)
  ModelFileFlags model_files;  // a model file's --ignore-contacts, --package-path
};

// --scenario NAME (run, figure): rebuilds the loaded lab under the rubric scenario's patch and noise
// seed exactly as the grader does (grading/scenario.h scenarioConfig: the lab's and the scenario's,
// the same for every submission). --duration still wins. Nothing happens for an empty name; throws InputError (an
// unknown name lists the rubric's).
void applyScenario(LoadedLab& loaded, const std::string& scenario, std::optional<double> duration);
// {"lab", <options as the config sets them>, "gains": {every gain's value}}: the lab's defaults as a submission.
json defaultsSubmission(const json& config, const std::string& lab);
// The lab's name for people: its JSON "title" up to the first ": " ("Impedance control"), else its id.
std::string labDisplayName(const json& config, const std::string& lab);
// Where a command writes by default: out/LAB/SUB, or out/LAB/scenarios/NAME/SUB under a scenario.
std::filesystem::path defaultOut(const std::string& lab, const std::string& scenario, const std::string& sub = "");

// The word that runs this dynlab in a shell: "dynlab" when that is what PATH finds, else its
// absolute path (a build tree's binary) as a shell word, so a printed command runs as printed.
std::string dynlabProgram();

// "key = value unit, ..." of every top-level number of a lab's agreement (run, bench).
std::string describeAgreement(const Lab& lab, const json& agreement);

int listLabs();
int runLab(const RunArgs& args);
int gradeOne(const GradeArgs& args);
int gradeReplay(const GradeArgs& args);
int gradeBatch(const GradeArgs& args);  // app/cli/course/batch.cpp
int writeAutograderZip(const std::string& lab, const std::string& out);
// Lecture figures: plots of trace columns and rendered stills (app/cli/figures/figure.cpp).
int figure(const FigureArgs& args);
int printSchema(const std::string& lab);
int bench(const BenchArgs& args);
// dynlab bench --scaling: hand ABA, hand CRBA + Cholesky and Bullet on chains of 3 … 1,000 links.
int benchScaling(const BenchArgs& args);
// Grades both, prints a table per test, writes OUT/comparison.md and OUT/plots/ (app/cli/figures/compare.cpp).
int compare(const CompareArgs& args);
// Prints each lesson with both scores; exit 0 when all hold, 1 when one does not, 2 on bad input.
int lessons(const LessonsArgs& args);
// Prints each contract check with ok/FAIL and one line, the default gains', examples' and instructor
// answers' shares and the passive drift; exit 0 when all pass, 1 when one fails, 2 on bad input.
int checkLab(const CheckLabArgs& args);  // app/cli/authoring/check_lab.cpp
int newLab(const NewLabArgs& args);      // app/cli/authoring/new_lab.cpp
// Replaces this process with dynlab-ui (next to /proc/self/exe); returns only on failure (1).
int openUi(const UiArgs& args);
// CPU cost of grading the lab's instructor/good.json (app/cli/bench/bench_grade.cpp); empty if none.
json gradeThroughput(const std::string& lab, int repeats);

}  // namespace dyn::app
