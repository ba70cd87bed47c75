// What every lab's JSON shares, parsed once here for all labs:
//   "simulation": {"dt", "duration", "integrator", "drift", "baumgarte": {"zeta", "omega"}, "exercise_duration"}
//   "gains":      {"<name>": {"value", "min", "max", "unit", "doc"}, ...}
// (submission options: labs/submission.h). Errors are InputErrors naming file and JSON path.
#pragma once
#include <cstddef>
#include <initializer_list>
#include <map>
#include <string>
#include <vector>

#include "labs/config.h"
#include "physics/integrate.h"

namespace dyn {

inline constexpr double kMinDt = 1e-6, kMaxDt = 0.05;  // s
inline constexpr double kMaxGain = 1e9;                  // |min|, |max| of a declared gain

// The one bound on a run's work, however the run is asked for (a lab's JSON, a model file's
// <option timestep>, --duration or --dt on any command, Python's arguments): its steps (duration / dt),
// its trace's memory (a row of doubles per step) and the frames drawn of it. Commands check it before
// they simulate; buildLab, runEngine and the frame writer (app/shared/movie.h) hold it again.
inline constexpr double kMaxSteps = 2e6;         // steps of one run
inline constexpr double kMaxTraceBytes = 512e6;  // one run's trace: (steps + 1) rows × columns × 8 bytes
inline constexpr double kMaxFrames = 36000;      // frames drawn of one run: 20 minutes at 30 a second

// Why a run of `duration` s at step dt (called `step` in the sentence: "dt", "timestep") with a trace
// of `columns` columns is over the bound, naming it: "timestep 1e-09 s over 2 s is 2e+09 steps, more
// than the 2e+06 a run may take", or "a trace of 2e+06 rows × 300 columns is 4.8 GB, more than the
// 512 MB a run's trace may hold"; "" when it fits (columns 0: the steps alone).
std::string runBoundProblem(double dt, double duration, std::size_t columns = 0, const std::string& step = "dt");
// The same for the frames drawn at `fps` a second of simulated time over `duration` s.
std::string frameBoundProblem(double duration, double fps);

struct SimulationSettings {
  StepOptions step;
  double duration = 1;           // s: the run's
  double exercise_duration = 1;  // s: the exercise's own, when a run is made shorter or longer (setRunDuration)
};

// config's run made `duration` s long (--duration, Python's duration=, check-lab's short runs): the
// exercise's own duration is kept as "simulation/exercise_duration", so what is checked against the
// exercise (a metric's window) is not refused because one run is shorter.
void setRunDuration(json& config, double duration);

// setRunDuration for a duration someone asked for (--duration, Python's duration=): in (0, 3600] s and
// within the run bound at the config's dt, else InputError(who, option, ...) naming the option.
void requestRunDuration(json& config, double duration, const std::string& who, const std::string& option);

// What a lab's mechanism can do with the shared options: drift "independent" needs a mechanism that
// rebuilds its dependent coordinates from the independent ones (ConstrainedSystem::recoverDependent).
enum class IndependentForm { No, Yes };

// The "simulation" block (pass config["simulation"]); an option the lab cannot honour is refused here,
// with a sentence, not at t = 0.
SimulationSettings parseSimulation(const JsonView& simulation, IndependentForm form = IndependentForm::No);

// The "gains" block: exactly the names given, each {"value", "min", "max"} with min ≤ value ≤ max
// and optional "unit" and "doc" strings; returns name → value.
std::map<std::string, double> parseGains(const JsonView& gains, std::initializer_list<const char*> names);
// The same for names known only at run time (a data-defined lab's); a key not among them is refused.
std::map<std::string, double> parseGains(const JsonView& gains, const std::vector<std::string>& names);

// The two optional blocks a C++ lab's config may carry beside its own: "metrics" {settle_time: when
// the metrics' windows start, s, in [0, 1e6]} and "drawing" {arrow_scale: m per N of a force arrow,
// positive, ≤ 1e3}. Each value is left as it is when its block is absent.
void parseMetricsAndDrawing(const JsonView& config, double& settle_time, double& arrow_scale);

// The simulation block's scheme in words, e.g. "rk4 + projection".
std::string schemeName(const StepOptions& step);

// A merge patch giving any lab the first-order scheme (semi-implicit Euler + Baumgarte drift
// correction: one dynamics evaluation per step, the order of a typical reference engine's step).
json firstOrderPatch();

// The merge patch that turns any lab's controller off (τ = 0): every lab accepts it.
json passivePatch();

}  // namespace dyn
