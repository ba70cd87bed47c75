// The lab contract (labs/lab.h) checked on one lab, as a list of named results: `dynlab check-lab
// LAB` prints them, and tests/labs/lab_checks.h asserts each on every registered lab (one copy).
//   config          the default config builds; its shared simulation block parses
//   examples        examples/*.json (and instructor/*.json) are non-empty, apply strictly, match the schema
//   engines         hand and Bullet run 200 steps with finite values
//   drift           "drift": "independent" runs on φ = 0 or is refused at /simulation/drift
//   passive energy  with passivePatch() (τ = 0) the energy stays within the lab's stated tolerance
//   metrics         the rubric's plot and watchdog columns exist; every rubric and leaderboard metric
//                   exists, finite, for every submission option choice (metrics + screening)
//   advice          every advice entry names a law that exists and gains that law reads; none
//                   tells a law to use itself (grading/advice.h)
//   grading         every example and every option choice grades to a valid results.json
//   defaults        the default gains score within the band (20–50 %: a weak, stable start)
//   plots           every simulated test of the defaults' grade has its plot on disk
//   lesson ...      each rubric lesson holds (grading/lessons.h); the rubric states at least one
//   doing nothing   every gain at its minimum scores below the defaults
//   instructor ...  each instructor answer scores ≥ 90 %
//   untuned ...     each instructor/untuned/*.json (the handout's round textbook gains) scores < 90 %
//   render          a frame of the scene renders non-blank, with and without the panel (OSMesa)
//   cli             `dynlab figure`, `dynlab run` (both engines, whole run), `dynlab grade`: exit 0
//   readme numbers  each number the README marks as measured agrees with that run (app/cli/authoring/readme_numbers.h)
#pragma once
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "labs/lab.h"

namespace dyn {

struct LabCheck {
  std::string check;   // its name (above)
  bool ok = false;
  std::string detail;  // one line: what was measured, or the first thing that is wrong
};

struct LabCheckOptions {
  std::string work_dir;      // an existing folder for the submissions, plots and runs written
  std::string config_file;   // the file config was read from: the checks name it, the grader reads it
                             // (empty: a scratch config.json in work_dir, named "config.json")
  std::string examples_dir;  // default: <lab_dir>/examples, then <lab_dir>/instructor's answers too
  std::string lab_dir;       // where the lessons' paths start (default: the default config's folder)
  std::string instructor_dir;  // the full-credit answers (default: <lab_dir>/instructor; "-": none)
  std::pair<double, double> defaults_band{0.2, 0.5};  // the share of points the default gains score
  std::string dynlab_binary;  // runs the cli check with this dynlab (empty: no cli check)
};

struct LabCheckReport {
  std::vector<LabCheck> checks;
  double defaults_share = NAN;                               // of the points
  std::vector<std::pair<std::string, double>> example_shares;     // examples/: file name → share
  std::vector<std::pair<std::string, double>> instructor_shares;  // file name → share
  // The passive run: max |E − E0|, E0, the lab's stated relative tolerance, the duration (s).
  double passive_drift = NAN, passive_e0 = NAN, passive_tolerance = NAN, passive_duration = NAN;
  bool ok() const;
};

// Every check on one lab (config: its default config, or a test's). Never throws for what the lab
// does wrong: an exception inside a check is that check's failure.
LabCheckReport checkLab(const LabEntry& entry, const json& config, const LabCheckOptions& options);

// The JSON files of a folder, sorted (none when it does not exist).
std::vector<std::string> jsonFiles(const std::string& dir);

}  // namespace dyn
