// dynlab.Lab; see lab_object.h. Every number comes from the core (labs/, grading/) exactly as the
// CLI's `dynlab run` gets it: runWatched under the rubric's watchdog, Lab::metrics, Lab::agreement.
#include "app/python/lab_object.h"

#include <limits>

#include "grading/grade.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "grading/student.h"
#include "labs/numbers.h"
#include "labs/submission.h"

namespace dyn::python {

LabObject::LabObject(const std::string& name, const std::string& config_file, const std::string& student) {
  // open() would stop at a NUL and read another file.
  if (config_file.find('\0') != std::string::npos) throw InputError(config_file, "", "expected a path without a NUL byte");
  plant_ = studentPlant(student, "student", kArgument);
  loaded_ = loadLab(name, config_file, "", std::nullopt, plant_);
}

py::dict LabObject::gains() const {
  py::dict out;
  for (const auto& [name, g] : loaded_.config.at("gains").items()) out[py::str(name)] = toPython(g.at("value"));
  return out;
}

py::dict LabObject::gainInfo() const {
  py::dict out;
  for (const auto& [name, g] : loaded_.config.at("gains").items()) {
    py::dict d;
    for (const char* key : {"value", "min", "max"}) d[key] = toPython(g.at(key));
    d["unit"] = g.value("unit", "");
    d["doc"] = g.value("doc", "");
    out[py::str(name)] = d;
  }
  return out;
}

py::list LabObject::columns() const {
  py::list out;
  for (const auto& c : loaded_.lab->columns()) out.append(c);
  return out;
}

py::dict LabObject::units() const {
  py::dict out;
  for (const auto& c : loaded_.lab->columns()) out[py::str(c)] = loaded_.lab->unit(c);
  return out;
}

void LabObject::apply(py::handle object, const std::string& source) {
  std::string file = source;
  json sub;
  if (asPath(object, file)) sub = loadJsonFile(file, 1u << 20);
  else sub = toJson(object, source);
  // Validated in full before anything changes: a bad gain leaves the lab as it was.
  json config = applySubmission(loaded_.config, JsonView(sub, file), name(), false);
  auto lab = buildLab(*loaded_.entry, config, file);
  loaded_.config = std::move(config);
  loaded_.lab = std::move(lab);
}

json LabObject::submission() const {
  // As the tuning window saves one: every gain as a double, and each option as the config sets it.
  json sub = {{"lab", name()}, {"gains", json::object()}};
  for (const auto& [n, g] : loaded_.config.at("gains").items()) sub["gains"][n] = g.at("value").get<double>();
  const json options = loaded_.config.value("submission_options", json::object());
  for (const auto& [n, o] : options.items()) {
    const json::json_pointer target(o.at("target").get<std::string>());
    if (loaded_.config.contains(target)) sub[n] = loaded_.config.at(target);
  }
  return sub;
}

bool Interruptible::operator()() {
  if (pending_) return true;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() == 0) return false;
  pending_.emplace();  // takes the exception the handler raised (KeyboardInterrupt for Ctrl-C)
  return true;
}

void Interruptible::rethrow() {
  if (pending_) {
    py::error_already_set e = std::move(*pending_);
    pending_.reset();
    throw e;
  }
}

py::dict LabObject::run(const std::string& engine, std::optional<double> duration, const std::string& scenario) const {
  if (engine != "hand" && engine != "bullet" && engine != "both")
    throw InputError(kArgument, "engine", "expected \"hand\", \"bullet\" or \"both\", got \"" + engine + "\"");
  // The lab to run: the current config, under a rubric scenario (seeded from this submission, as
  // the grader seeds it), with the duration given (the CLI's checks and messages).
  json config = loaded_.config;
  std::string source = loaded_.config_file;
  const bool has_rubric = config.contains("rubric");
  std::optional<Rubric> rubric;
  if (has_rubric) rubric = parseRubric(JsonView(config, loaded_.config_file));
  if (!scenario.empty()) {
    if (!rubric) throw InputError(kArgument, "scenario", "expected a lab with a rubric; " + loaded_.config_file + " has none");
    const Scenario& sc = findScenario(*rubric, scenario, "scenario");
    config = scenarioConfig(config, *rubric, sc, loaded_.entry->name, loaded_.config_file);
    source = loaded_.config_file + " (scenario " + sc.name + ")";
  }
  if (duration) requestRunDuration(config, *duration, kArgument, "duration");
  auto built = buildLab(*loaded_.entry, config, source);
  const Lab& lab = *built;
  if (lab.duration() < lab.dt())
    throw InputError(kArgument, "duration",
                     "expected at least one step (dt = " + fmtNumber(lab.dt()) + " s), got " + exactNumber(lab.duration()) + " s");
  // `dynlab run`'s watchdog: the rubric's limits, no step budget.
  Watchdog watchdog;
  if (rubric) {
    checkColumns(*rubric, lab.columns(), loaded_.config_file);
    watchdog = rubric->watchdog;
  }
  watchdog.max_steps = std::numeric_limits<long>::max();

  // The runs, without the GIL; Ctrl-C is heard every 1024 steps.
  std::optional<WatchedRun> hand, bullet;
  Interruptible interrupted;
  // Without the GIL only what this call owns: the lab it built, its watchdog, a copy of the config's name.
  const std::string config_file = loaded_.config_file;
  {
    py::gil_scoped_release release;
    const StopRequest stop = [&] { return interrupted(); };
    if (engine != "bullet") hand = runWatched(lab, Engine::Hand, watchdog, Deadline::max(), config_file, stop);
    if (engine != "hand" && !(hand && hand->interrupted))
      bullet = runWatched(lab, Engine::Bullet, watchdog, Deadline::max(), config_file, stop);
  }
  interrupted.rethrow();

  // summary.json's fields, as `dynlab run` writes them, and the traces as arrays.
  json summary = {{"lab", name()}, {"config", loaded_.config_file}, {"scenario", scenario.empty() ? json(nullptr) : json(scenario)},
                  {"dt", lab.dt()}, {"duration", lab.duration()}, {"dynlab_version", DYNLAB_VERSION}};
  std::string status;
  py::dict traces;
  for (auto* r : {&hand, &bullet}) {
    if (!*r) continue;
    const char* e = r == &hand ? "hand" : "bullet";
    summary["engines"][e] = engineSummary(lab, **r);
    if (!(*r)->failure.empty()) status += (status.empty() ? "" : "; ") + std::string(e) + ": " + (*r)->failure;
    traces[e] = traceArrays((*r)->trace);
  }
  if (hand && bullet && hand->failure.empty() && bullet->failure.empty()) summary["agreement"] = lab.agreement(hand->trace, bullet->trace);
  summary["units"] = json::object();
  for (const auto& c : lab.columns())
    if (!lab.unit(c).empty()) summary["units"][c] = lab.unit(c);
  summary["status"] = status.empty() ? "ok" : status;
  py::dict out = toPython(summary);
  out["traces"] = traces;
  // Kept for frame() and video(): this run's lab and traces (a stopped run's too: it shows the blow-up).
  auto last = std::make_shared<LastRun>();
  if (hand) last->hand = std::move(hand->trace);
  if (bullet) last->bullet = std::move(bullet->trace);
  last->lab = std::move(built);
  last_ = std::move(last);
  return out;
}

py::dict LabObject::screen() const {
  const ScreenResult s = screenLoops(*loaded_.lab);
  py::dict out;
  out["metrics"] = toPython(s.metrics);
  py::list notes;
  for (const auto& n : s.notes) notes.append(n);
  out["notes"] = notes;
  out["unstable"] = s.unstable;
  return out;
}

}  // namespace dyn::python
