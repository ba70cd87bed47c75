// A lab's rubric, as data in its JSON ("rubric"): scenarios (merge patches on the config, applied
// after the student's gains), tests that turn one metric of one scenario into points with linear
// partial credit, and the watchdog that ends a run gone bad.
//
//   "rubric": {
//     "seed_target": "/controller/seed",            // where each scenario's derived seed is written
//     "scenarios": {"heavy": {"about": "bob mass +20 %", "patch": {"plant": {"mass": 1.2}}}},
//     "watchdog": {"max_steps": 100000, "limits": [{"column": "theta", "min": -3, "max": 3,
//                  "what": "the pendulum angle"}]},
//     "tests": [{"name": "...", "scenario": "nominal", "metric": "theta_rms", "full": 0.003,
//                "zero": 0.03, "points": 4, "visibility": "visible",
//                "plot": {"columns": ["theta"], "reference": "theta_d", "band": 0.003, "ylabel": "theta (rad)"}}],
//     (an x–y plot, the path in the plane: "plot": {"x": "x", "columns": ["y"], "reference": "y_d",
//      "reference_x": "x_d"}; no band, no hatched window)
//     "leaderboard": [{"name": "tracking RMS (mrad)", "scenario": "nominal", "metric": "theta_rms",
//                      "scale": 1000, "order": "asc"}],
//     "lessons": [{"about": "an integral force law survives the delay, a proportional one does not",
//                  "better": "examples/integral.json", "worse": "examples/proportional.json", "margin": 0.15}]
//   }
// A lesson is the rubric's claim about the lecture: graded by this rubric, the submission "better"
// (a path relative to the config's folder) scores at least margin × maxScore() more than "worse".
// tests/labs checks every lab's lessons; `dynlab lessons LAB` prints them.
// Metrics come from the lab (Lab::metrics of the scenario's trace) or from screening the gains on
// the linearised loops (<loop>_delay_margin, <loop>_max_real_pole, <loop>_damping, ...).
#pragma once
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "labs/config.h"

namespace dyn {

struct ColumnLimit {
  std::string column, what;
  double min = -INFINITY, max = INFINITY;
};

struct Watchdog {
  long max_steps = 1000000;  // step budget per scenario
  std::vector<ColumnLimit> limits;
};

struct PlotRequest {
  std::vector<std::string> columns;
  std::string reference;  // optional column the response should follow
  double band = 0;        // half-width of the tolerance band around the reference (or zero)
  std::string ylabel;
  std::string x;            // x–y plot: the columns against this column (empty: against t)
  std::string reference_x;  // x–y plot: the reference against this column (default: x)
  std::string xlabel;       // x–y plot: its x label (empty: the x columns with their unit)
};

struct RubricTest {
  std::string name, scenario, metric, visibility = "visible";
  double full = 0, zero = 1, points = 1;
  std::optional<PlotRequest> plot;
};

struct LeaderboardEntry {
  std::string name, scenario, metric, order = "asc";
  double scale = 1;
};

struct Lesson {
  std::string about, better, worse;  // better/worse: paths relative to the config's folder
  double margin = 0;                 // the least lead, as a share of the rubric's points
};

struct Scenario {
  std::string name, about;
  json patch;  // RFC 7386 merge patch on the lab config
};

struct Rubric {
  std::vector<Scenario> scenarios;  // "nominal" first, then by name
  std::string seed_target;                               // JSON pointer, or empty
  Watchdog watchdog;
  std::vector<RubricTest> tests;
  std::vector<LeaderboardEntry> leaderboard;
  std::vector<Lesson> lessons;
  const Scenario* scenario(const std::string& name) const;
  double maxScore() const;
};

// Reads and validates config["rubric"]; throws InputError naming file and JSON path.
Rubric parseRubric(const JsonView& config);

// Checks that every column the rubric names (plots, references, watchdog limits) is one of the
// lab's trace columns; throws InputError naming file and the JSON path otherwise.
void checkColumns(const Rubric& rubric, const std::vector<std::string>& columns, const std::string& file);

// Linear partial credit between the full-credit and zero-credit thresholds (either order):
//   fraction = clamp((zero − m) / (zero − full), 0, 1); non-finite m scores 0.
double partialCredit(double metric, double full, double zero);

// Writes a scenario's derived seed at rubric.seed_target (nothing if it has none); throws
// InputError naming file and /rubric/seed_target if the patched config has no object there.
void writeSeed(json& config, const Rubric& rubric, std::uint64_t seed, const std::string& file,
               const std::string& scenario);

}  // namespace dyn
