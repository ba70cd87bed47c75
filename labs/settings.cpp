// The simulation block and declared gains every lab shares; see settings.h.
#include "labs/settings.h"

#include <algorithm>

namespace dyn {

SimulationSettings parseSimulation(const JsonView& sim, IndependentForm form) {
  SimulationSettings s;
  sim.onlyKeys({"dt", "duration", "integrator", "drift", "baumgarte", "exercise_duration"});
  s.step.dt = sim["dt"].positive();
  if (s.step.dt > kMaxDt || s.step.dt < kMinDt) sim["dt"].inRange(kMinDt, kMaxDt);
  s.duration = sim["duration"].positive();
  if (s.duration / s.step.dt > kMaxSteps)
    sim["duration"].fail("expected at most 2e6 steps (duration/dt); a trace of 2e6 rows is ~300 MB");
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

std::string schemeName(const StepOptions& step) {
  return std::string(name(step.integrator)) + " + " + name(step.drift.kind);
}

json firstOrderPatch() {
  return {{"simulation", {{"integrator", name(Integrator::SemiImplicitEuler)}, {"drift", name(Drift::Baumgarte)}}}};
}

json passivePatch() { return {{"controller", {{"kind", "none"}}}}; }

}  // namespace dyn
