// The simulation block and declared gains every lab shares; see settings.h.
#include "labs/settings.h"

#include <algorithm>
#include <cmath>

#include "labs/numbers.h"

namespace dyn {

SimulationSettings parseSimulation(const JsonView& sim, IndependentForm form) {
  SimulationSettings s;
  sim.onlyKeys({"dt", "duration", "integrator", "drift", "baumgarte", "exercise_duration"});
  s.step.dt = sim["dt"].positive();
  if (s.step.dt > kMaxDt || s.step.dt < kMinDt) sim["dt"].inRange(kMinDt, kMaxDt);
  s.duration = sim["duration"].positive();
  if (const std::string problem = runBoundProblem(s.step.dt, s.duration); !problem.empty()) sim["duration"].fail(problem);
  s.exercise_duration = sim.has("exercise_duration") ? sim["exercise_duration"].positive(1e6) : s.duration;
  parseIntegrator(sim["integrator"].oneOf({"semi_implicit_euler", "rk4"}), s.step.integrator);
  parseDrift(sim["drift"].oneOf({"none", "baumgarte", "projection", "independent"}), s.step.drift.kind);
  if (s.step.drift.kind == Drift::Independent && form == IndependentForm::No)
    sim["drift"].fail("expected none, baumgarte or projection: this lab's mechanism has no independent-coordinate form "
                      "(\"independent\" rebuilds the dependent coordinates from the independent ones, which only the "
                      "slider crank and the grasp can)");
  if (sim.has("baumgarte")) {
    sim["baumgarte"].onlyKeys({"zeta", "omega"});
    s.step.drift.zeta = sim["baumgarte"]["zeta"].positive(1e3);
    s.step.drift.omega = sim["baumgarte"]["omega"].positive(1e6);
  }
  return s;
}

void setRunDuration(json& config, double duration) {
  json& sim = config["simulation"];
  if (sim.is_object() && !sim.contains("exercise_duration") && sim.contains("duration")) sim["exercise_duration"] = sim["duration"];
  sim["duration"] = duration;
}

void requestRunDuration(json& config, double duration, const std::string& who, const std::string& option) {
  if (!(duration > 0) || duration > 3600) throw InputError(who, option, "expected a duration in (0, 3600] s");
  // The steps it makes at the lab's dt, named as the option's (buildLab names the trace's memory).
  const json& dt = config["simulation"]["dt"];
  if (const std::string problem = runBoundProblem(dt.is_number() ? dt.get<double>() : 0.0, duration); !problem.empty())
    throw InputError(who, option, problem);
  setRunDuration(config, duration);
}

std::string runBoundProblem(double dt, double duration, std::size_t columns, const std::string& step) {
  if (!(dt > 0) || !std::isfinite(dt)) return step + " " + fmt("%g", dt) + " s is not a positive step";
  const double steps = duration / dt;
  if (!(steps <= kMaxSteps))  // NaN too
    return step + " " + fmt("%g", dt) + " s over " + fmt("%g", duration) + " s is " + fmt("%g", steps) + " steps, more than the " +
           fmt("%g", kMaxSteps) + " a run may take";
  const double rows = std::floor(steps) + 1, bytes = rows * double(columns) * sizeof(double);
  if (bytes > kMaxTraceBytes)
    return "a trace of " + fmt("%g", rows) + " rows × " + std::to_string(columns) + " columns is " + fmt("%.3g", bytes / 1e6) +
           " MB, more than the " + fmt("%g", kMaxTraceBytes / 1e6) + " MB a run's trace may hold (" + step + " " + fmt("%g", dt) +
           " s over " + fmt("%g", duration) + " s)";
  return "";
}

std::string frameBoundProblem(double duration, double fps) {
  const double frames = std::floor(duration * fps + 1e-6) + 1;  // a trace's duration, (rows − 1)·dt, may fall short by an ulp
  if (frames <= kMaxFrames) return "";
  return fmt("%g", duration) + " s at " + fmt("%g", fps) + " frames a second is " + fmt("%g", frames) + " frames, more than the " +
         fmt("%g", kMaxFrames) + " a run may draw";
}

std::map<std::string, double> parseGains(const JsonView& g, std::initializer_list<const char*> names) {
  g.onlyKeys(names);
  return parseGains(g, std::vector<std::string>(names.begin(), names.end()));
}

std::map<std::string, double> parseGains(const JsonView& g, const std::vector<std::string>& names) {
  g.requireObject();
  for (const auto& [key, value] : g.raw().items()) {
    (void)value;
    if (std::find(names.begin(), names.end(), key) != names.end()) continue;
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    g[key].fail("unknown key \"" + key + "\" (expected one of: " + list + ")");
  }
  std::map<std::string, double> out;
  for (const auto& key : names) {
    const JsonView d = g[key];
    d.onlyKeys({"value", "min", "max", "unit", "doc"});
    for (const char* text : {"unit", "doc"})
      if (d.has(text)) d[text].string();
    const double lo = d["min"].inRange(-kMaxGain, kMaxGain), hi = d["max"].inRange(lo, kMaxGain);
    out[key] = d["value"].inRange(lo, hi);
  }
  return out;
}

void parseMetricsAndDrawing(const JsonView& config, double& settle_time, double& arrow_scale) {
  if (config.has("metrics")) {
    config["metrics"].onlyKeys({"settle_time"});
    settle_time = config["metrics"]["settle_time"].inRange(0, 1e6);
  }
  if (config.has("drawing")) {
    config["drawing"].onlyKeys({"arrow_scale"});
    arrow_scale = config["drawing"]["arrow_scale"].positive(1e3);
  }
}

std::string schemeName(const StepOptions& step) {
  return std::string(name(step.integrator)) + " + " + name(step.drift.kind);
}

json firstOrderPatch() {
  return {{"simulation", {{"integrator", name(Integrator::SemiImplicitEuler)}, {"drift", name(Drift::Baumgarte)}}}};
}

json passivePatch() { return {{"controller", {{"kind", "none"}}}}; }

}  // namespace dyn
