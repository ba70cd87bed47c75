// TuningSession: what the tuning window tunes and plays, with no GL in it. The lab's config with
// the student's gains and options applied (labs/submission.h: the same validation as grading),
// the hand and/or Bullet run advanced a fixed step at a time under the rubric's watchdog (the
// grader's RowWatch, same sentences), running metrics, screening notes, and the gains saved as a
// submission `dynlab grade` accepts. Everything goes through the Lab interface and the lab's JSON
// ("gains", "submission_options", "rubric"), so any lab works unchanged.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "grading/scenario.h"
#include "labs/lab.h"
#include "labs/run.h"

namespace dyn::ui {

// A gain as the lab's JSON declares it: "gains": {"kp": {"value", "min", "max", "unit", "doc"}}.
struct GainSpec {
  std::string name, unit, doc;
  double min = 0, max = 0, lab_default = 0;
};

// A submission option: "submission_options": {"law": {"target", "choices", "doc"}}.
struct OptionSpec {
  std::string name, doc, target;
  std::vector<std::string> choices;
  std::string lab_default;
};

enum class EngineChoice { Hand, Bullet, Both };
const char* name(EngineChoice e);
EngineChoice parseEngineChoice(const std::string& s);  // "hand" | "bullet" | "both"; throws InputError

class TuningSession {
 public:
  // Loads LAB's config (default path unless config_file), applies an optional gains file, builds
  // the lab and starts a run. Throws InputError on bad input (nothing is opened). With a scenario,
  // every run is under that rubric scenario exactly as the grader runs it (grading/scenario.h
  // scenarioConfig), its noise seeded as grading submission() would seed it; with a plant, on that
  // student's plant (labs/variants.h).
  TuningSession(const std::string& lab, const std::string& config_file = "", const std::string& gains_file = "",
                const std::string& scenario = "", const PlantChoice& plant = {});
  // A lab already built in memory, its config its own defaults (a model file: labs/generic/model_lab.h).
  explicit TuningSession(LoadedLab loaded);

  // ---- what can be tuned --------------------------------------------------------------------
  const std::string& labName() const { return lab_name_; }
  std::string title() const;  // the config's "title", else the lab name; + " — scenario NAME" under one
  const std::string& scenario() const { return scenario_; }  // the rubric scenario, or ""
  const std::vector<GainSpec>& gainSpecs() const { return gain_specs_; }
  const std::vector<OptionSpec>& optionSpecs() const { return option_specs_; }
  double gain(const std::string& name) const;
  const std::string& option(const std::string& name) const;
  // Validated (bounds, choices); throw InputError. They take effect at the next restart().
  void setGain(const std::string& name, double value);
  void setOption(const std::string& name, const std::string& value);
  // NAME=VALUE for a gain or an option (the --set of scripted runs); throws InputError.
  void set(const std::string& assignment);
  void resetToLabDefaults();

  // ---- the submission ----------------------------------------------------------------------
  // {"lab": ..., <options>, "gains": {...}}: every declared gain, checked as `dynlab grade` checks.
  json submission() const;
  // Writes submission() to path atomically (a temporary beside it, then rename); throws
  // std::runtime_error naming the path. Never leaves a partial file.
  void saveSubmission(const std::string& path) const;

  // ---- the run -----------------------------------------------------------------------------
  EngineChoice engine() const { return engine_; }
  void setEngine(EngineChoice e) { engine_ = e; }  // takes effect at the next restart()
  // Rebuilds the lab from the current gains and options and starts again from t = 0 (the first
  // row, t = 0, is computed at once). A config the lab rejects becomes problem(), never a throw.
  void restart();
  // Advances every run by up to n steps; a run stops at its duration, when the watchdog trips, or
  // when its engine reports a failure. Returns the steps the primary run took.
  long advance(long n);
  bool finished() const;          // the primary run is over (duration reached or stopped)
  const std::string& problem() const { return problem_; }  // why the primary run stopped, or ""
  const std::string& ghostProblem() const { return ghost_problem_; }  // the Bullet ghost's
  bool hasRows() const { return primary().rows() > 0; }
  const Trace& primary() const;   // hand trace (Bullet's when the engine is Bullet alone)
  const Trace* ghost() const;     // the Bullet trace when both engines run, else null
  std::size_t row() const { return primary().rows() ? primary().rows() - 1 : 0; }  // shown row
  double time() const;            // t of the shown row
  const Lab* lab() const { return lab_.get(); }
  const json& config() const { return effective_config_; }

  // Lab::metrics of the primary trace so far ({} if there are no rows or the lab throws).
  json metrics() const;
  // The same, cached for the panel: recomputed whenever the shown row or the run changes, so it
  // always describes the frame on screen (never a frame, or 100 steps, behind).
  const json& currentMetrics();

  // What the live plots show at the shown row: the lab's overlay series (every step of their
  // window, the last one the shown row's), then, when column is a trace column, that column over
  // the last two seconds, every step. At a watchdog stop a plot ends on the value that tripped it.
  std::vector<Series> livePlots(int column = -1) const;
  // One sentence per linearised loop (grading's screening), computed at restart().
  const std::vector<std::string>& screening() const { return screen_notes_; }
  bool screeningUnstable() const { return screen_unstable_; }
  // What the lab's loading said once (a model file's notes: collision geoms, stiff servos, ...).
  void setNotes(std::vector<std::string> notes) { notes_ = std::move(notes); }
  const std::vector<std::string>& notes() const { return notes_; }

 private:
  struct Run {
    Engine engine;
    std::unique_ptr<Simulation> sim;
    Trace trace;
    std::string stopped;  // watchdog or engine failure sentence
    bool done = false;
  };
  bool stepRun(Run& run);
  void init(const std::string& lab, LoadedLab loaded, const json& plain, std::vector<std::string> order,
            const std::string& source, const std::string& scenario);

  std::string lab_name_, config_file_, source_;
  const LabEntry* entry_ = nullptr;
  json file_config_;       // the lab config as loaded (+ gains file)
  json effective_config_;  // with the current gains and options
  std::vector<GainSpec> gain_specs_;
  std::vector<OptionSpec> option_specs_;
  json gains_ = json::object();    // name -> value
  json options_ = json::object();  // name -> choice
  EngineChoice engine_ = EngineChoice::Hand;
  Watchdog watchdog_;
  Rubric rubric_;          // the lab's rubric (when it has one): scenarios and seed target
  std::string scenario_;   // the rubric scenario every run is under, or ""
  std::unique_ptr<Lab> lab_;
  std::unique_ptr<RowWatch> watch_;
  std::vector<Run> runs_;  // [0] primary, [1] ghost
  Trace empty_;
  std::string problem_, ghost_problem_;
  std::vector<std::string> screen_notes_, notes_;
  bool screen_unstable_ = false;
  long generation_ = 0;  // counts restarts: a new run is never mistaken for the cached one
  struct {
    long generation = -1;
    std::size_t row = 0;
    bool finished = false;
    json value = json::object();
  } metrics_cache_;
};

}  // namespace dyn::ui
