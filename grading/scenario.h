// One rubric scenario of one submission: screen the gains on the lab's linearised loops, then run
// the hand-written engine under the watchdog, and collect the metrics the rubric's tests read.
// Deterministic: fixed steps, the seed comes from the submission; only the wall-time budget reads
// a clock, and it only ever stops a run (reported as such, never scored as a result).
#pragma once
#include <chrono>
#include <functional>
#include <string>

#include "grading/rubric.h"
#include "labs/lab.h"

namespace dyn {

struct ScreenResult {
  json metrics = json::object();  // <loop>_delay_margin, <loop>_max_real_pole, <loop>_damping, ...
  std::vector<std::string> notes;  // one plain sentence per loop
  bool unstable = false;
};

// Poles and margins of every loop the lab reports (physics/linear.h).
ScreenResult screenLoops(const Lab& lab);

struct ScenarioRun {
  Trace trace;
  json metrics = json::object();  // lab metrics + screening metrics
  ScreenResult screen;
  std::string failure;    // plain sentence when the run was stopped ("unstable: ...") else empty
  double failure_time = -1;
  bool out_of_time = false;  // the wall-time budget ran out (nothing is scored from this run)
};

using Deadline = std::chrono::steady_clock::time_point;
// Asked every 1024 steps, with the deadline: true stops the run as a spent time budget does (a
// notebook's Ctrl-C; empty: never asked).
using StopRequest = std::function<bool()>;

// The watchdog's check of one trace row, shared by graded runs and the tuning window so both say
// the same sentence. Throws InputError (naming config_file) if a limit names a column the lab lacks.
class RowWatch {
 public:
  RowWatch(const Watchdog& watchdog, const std::vector<std::string>& columns, const std::string& config_file);
  // Empty while the row is fine, else "unstable: <what> left its safe range [..] at t = .. s (..)".
  std::string check(const std::vector<double>& row, double t) const;
  // "stopped: the run exceeded its step budget of N steps" once steps reaches the budget, else empty.
  std::string budget(long steps) const;
  long maxSteps() const { return max_steps_; }

 private:
  std::vector<std::string> columns_;
  std::vector<std::pair<int, ColumnLimit>> limits_;
  long max_steps_;
};

// One engine's run under the watchdog: the trace up to where it stopped, and why.
struct WatchedRun {
  Trace trace;
  std::string failure;  // the watchdog's sentence, the step budget, the time budget or the engine's own
  double failure_time = -1;
  bool out_of_time = false;
  bool interrupted = false;  // the stop request ended it (out_of_time too: nothing is scored from it)
};

// Runs one engine of the lab, checking every row with RowWatch, the step budget and (every 1024
// steps) the deadline and the stop request; `dynlab run` watches both engines with it, the grader
// the hand-written one.
WatchedRun runWatched(const Lab& lab, Engine engine, const Watchdog& watchdog, Deadline deadline,
                      const std::string& config_file, const StopRequest& stop = {});

// One engine's entry of a run's summary (`dynlab run`, Python's Lab.run): its status, whether it ran
// to its end, its trace's hash, and the lab's metrics only when it did (numbers over part of a run
// read as if they described all of it); a stopped run says when it stopped.
json engineSummary(const Lab& lab, const WatchedRun& run);

// Runs the lab's hand-written engine under the watchdog; throws InputError (naming config_file)
// if a watchdog limit names a column the lab does not have.
ScenarioRun runScenario(const Lab& lab, const Watchdog& watchdog, Deadline deadline,
                        const std::string& config_file, const StopRequest& stop = {});

// The config one rubric scenario runs on, exactly as the grader builds it: the submission's config
// (its gains applied) merged with the scenario's patch (RFC 7386), and the scenario's noise seed,
// derived from the lab's and the scenario's names alone, written at the rubric's seed_target: every
// submission meets the same noise, so none can be re-rolled by changing a gain (read or not) or the
// way the file is written. Used by the grader, `dynlab run/figure --scenario`, Python and the tuning
// window, so a scenario run locally is the graded one. Throws InputError (naming config_file) on a bad
// seed_target.
json scenarioConfig(const json& applied, const Rubric& rubric, const Scenario& scenario, const std::string& lab,
                    const std::string& config_file);

// The rubric's scenario NAME; else InputError("<command line>", option, the names it knows).
const Scenario& findScenario(const Rubric& rubric, const std::string& name, const std::string& option = "--scenario");

// Format a number for people: 4 significant digits.
std::string fmtNumber(double x);

}  // namespace dyn
